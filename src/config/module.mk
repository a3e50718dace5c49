# src/config: the machine INI's reader, its checks and the table of its keys
# (ncpar/config.h), also linked on their own into cnc-drive-sim
LIB_SRCS += $(wildcard src/config/*.c)
