# sources of src/lex, appended by the module
LIB_SRCS += $(wildcard src/lex/*.c)
LIB_CXXSRCS += $(wildcard src/lex/*.cpp)
