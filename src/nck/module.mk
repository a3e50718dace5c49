# sources of src/nck, appended by the module
LIB_SRCS += $(wildcard src/nck/*.c)
