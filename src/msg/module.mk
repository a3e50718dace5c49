# src/msg: the NCK's LCM transport (udpm://, LC02) and the pure helpers it
# shares with cnc-ctl (frames, command validation, state names, status JSON).
# The message types themselves are generated from lcm/*.lcm (GEN_OBJS).
LIB_SRCS += $(wildcard src/msg/*.c)
