# sources of src/rt, appended by the module
LIB_SRCS += $(wildcard src/rt/*.c)
