# cnc-drive-sim: a simulated CiA 402 drive on a (v)CAN interface. Linked from
# the CAN objects only, so it builds even while other modules are unfinished.
all: $(BUILD)/cnc-drive-sim

DRIVE_SIM_OBJS = $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/can-drive-sim/*.c) \
                   $(wildcard src/can/*.c) $(wildcard src/diag/*.c))

$(BUILD)/cnc-drive-sim: $(DRIVE_SIM_OBJS)
	$(Q)$(CC) $(ALL_CFLAGS) -o $@ $^
