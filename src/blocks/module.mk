# sources of src/blocks, appended by the module
LIB_SRCS += $(wildcard src/blocks/*.c)
LIB_CXXSRCS += $(wildcard src/blocks/*.cpp)
