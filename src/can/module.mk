# sources of src/can (CANopen / CiA 402 master over SocketCAN)
LIB_SRCS += $(wildcard src/can/*.c)
