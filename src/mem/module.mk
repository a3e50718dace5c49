# sources of src/mem, appended by the module
LIB_SRCS += $(wildcard src/mem/*.c)
