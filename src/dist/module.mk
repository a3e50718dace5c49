# src/dist: what the distributed NCK's HLC (the lcm backend) and its LLCs
# (cnc-axis) share: channel names, the setpoint codec, the LLC's buffer.
LIB_SRCS += $(wildcard src/dist/*.c)
