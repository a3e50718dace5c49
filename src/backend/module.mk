# sources of src/backend, appended by the module
LIB_SRCS += $(wildcard src/backend/*.c)
