# sources of src/motion, appended by the module
LIB_SRCS += $(wildcard src/motion/*.c)
