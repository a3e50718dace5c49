# cnc-drive-sim: a simulated CiA 402 drive on a (v)CAN interface. Linked from
# the CAN master's archive (src/can/module.mk), the sim plant and the INI
# reader (with its [KINS] keys) only, so it builds even while other modules are unfinished.
all: $(BUILD)/cnc-drive-sim

DRIVE_SIM_OBJS = $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/can-drive-sim/*.c) \
                   src/backend/sim.c src/backend/scale.c src/motion/config.c \
                   src/motion/config_io.c src/motion/config_kins.c src/motion/config_home.c $(wildcard src/inject/*.c)) \
                 $(BUILD)/src/kins/trt.o

$(BUILD)/cnc-drive-sim: $(DRIVE_SIM_OBJS) $(BUILD)/libncpar-can.a
	$(Q)$(CC) $(ALL_CFLAGS) -o $@ $^ -lm -linih
