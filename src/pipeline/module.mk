# sources of src/pipeline, appended by the module
LIB_SRCS += $(wildcard src/pipeline/*.c)
LIB_CXXSRCS += $(wildcard src/pipeline/*.cpp)
