# sources of src/can (CANopen / CiA 402 master over SocketCAN)
LIB_SRCS += $(wildcard src/can/*.c)

# The CAN master and the diagnostics it reports with, as one archive of the
# library's own objects for the programs that need nothing else
# (cnc-drive-sim, tests/rt's can-master-test): compiled once, one way, and
# built without waiting for the rest of the library. Other fragments name it
# by its path, $(BUILD)/libncpar-can.a (they may be read before this one).
$(BUILD)/libncpar-can.a: $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/can/*.c) src/diag/diag.c)
	@mkdir -p $(@D)
	$(Q)rm -f $@ && $(AR) rcs $@ $^
