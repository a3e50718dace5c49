# cnc-drive-sim: a simulated CiA 402 drive on a (v)CAN interface. Linked from
# the CAN master's archive (src/can/module.mk), the sim plant and the INI
# reader (with its [KINS] keys) only, so it builds even while other modules are unfinished.
all: $(BUILD)/cnc-drive-sim

DRIVE_SIM_OBJS = $(patsubst %.c,$(BUILD)/%.o,$(wildcard src/can-drive-sim/*.c) \
                   src/backend/sim.c src/backend/scale.c $(wildcard src/config/*.c) \
                   src/adcai/windows.c $(wildcard src/inject/*.c) \
                   src/sched/config.c src/sched/policy.c src/http/policy.c) \
                 $(BUILD)/src/kins/trt.o

# trt.o is C++ (Eigen): libstdc++ for what a sanitizer build of it needs
$(BUILD)/cnc-drive-sim: $(DRIVE_SIM_OBJS) $(BUILD)/libncpar-can.a
	$(Q)$(CC) $(ALL_CFLAGS) $(LDFLAGS) -o $@ $^ -lm -linih -lstdc++

# The drive's guarding of its master, tested on the host over a socket pair
# (no CAN needed): the drive's objects without its main; only sources and
# objects go to the compiler (its .d file adds headers to the prerequisites,
# which clang would take for headers to precompile).
$(BUILD)/tests/test_drive_guard: tests/unit/test_drive_guard.c \
        $(filter-out %/cnc_drive_sim.o,$(DRIVE_SIM_OBJS)) $(BUILD)/libncpar-can.a | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -Isrc/can-drive-sim -o $@ $(filter %.c %.o %.a,$^) \
	    -lcmocka -lm -linih -lstdc++

# The drive's own homing mode driven by the master's homing state machine
# (src/can/dhome.c) over a socket pair, the same way.
$(BUILD)/tests/test_drive_homing: tests/unit/test_drive_homing.c \
        $(filter-out %/cnc_drive_sim.o,$(DRIVE_SIM_OBJS)) $(BUILD)/libncpar-can.a | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -Isrc/can-drive-sim -o $@ $(filter %.c %.o %.a,$^) \
	    -lcmocka -lm -linih -lstdc++
