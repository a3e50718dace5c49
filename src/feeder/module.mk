# sources of src/feeder, appended by the module
LIB_SRCS += $(wildcard src/feeder/*.c)
LIB_CXXSRCS += $(wildcard src/feeder/*.cpp)
