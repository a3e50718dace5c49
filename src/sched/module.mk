# sources of src/sched, appended by the module
LIB_SRCS += $(wildcard src/sched/*.c)
