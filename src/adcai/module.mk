# sources of src/adcai, appended by the module
LIB_SRCS += $(wildcard src/adcai/*.c)
