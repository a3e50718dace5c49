# sources of src/analyzer, appended by the module
LIB_SRCS += $(wildcard src/analyzer/*.c)
LIB_CXXSRCS += $(wildcard src/analyzer/*.cpp)
