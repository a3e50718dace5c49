# sources of src/executor, appended by the module
LIB_SRCS += $(wildcard src/executor/*.c)
LIB_CXXSRCS += $(wildcard src/executor/*.cpp)
