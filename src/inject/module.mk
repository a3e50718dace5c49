# sources of src/inject (timing faults injected into the position loop,
# setpoint policies, miss limits), appended by the module
LIB_SRCS += $(wildcard src/inject/*.c)
