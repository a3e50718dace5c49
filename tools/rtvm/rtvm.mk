# PREEMPT_RT guest harness (tools/rtvm): included from the top Makefile.
#   make rtvm-deps   install qemu, busybox-static, the Debian RT kernel, rt-tests, can-utils
#   make test-rt     boot the RT kernel in qemu and run tests/rt/run-all inside it
#   make test-can-host   the CAN tests on this host when it can make vcan0, else a SKIP line
# RTVM_FLAGS passes options to tools/rtvm/run, e.g. RTVM_FLAGS="--tcg --timeout 600".

RTVM_FLAGS ?=
RTVM_TIMEOUT ?= 2100

.PHONY: rtvm-deps test-rt test-can-host

rtvm-deps:
	tools/rtvm/install-deps

# The guest runs the host's binaries from the project dir, so build first.
# run-all fails (and so does this target) when the guest kernel is not PREEMPT_RT.
test-rt: all
	RTVM_CACHE=$(abspath $(BUILD))/rtvm tools/rtvm/run --timeout $(RTVM_TIMEOUT) $(RTVM_FLAGS) -- \
	    env BUILD=$(BUILD) tests/rt/run-all

test-can-host: all
	$(Q)$(CAN_MASTER_TEST) --selftest
	$(Q)if why=$$(tools/rtvm/can-available); then \
	    echo "CAN tests on the host ($$why)"; \
	    tests/rt/vcan && BUILD=$(BUILD) tests/rt/can && BUILD=$(BUILD) tests/rt/can-dist; \
	else \
	    echo "SKIP: CAN bus tests on the host: $${why#no: }"; \
	fi

# The CAN master test program (tests/rt/can_master_test.c): linked with the CAN
# master's archive (src/can/module.mk) so it does not wait for the rest of the
# library.
CAN_MASTER_TEST = $(BUILD)/tests/rt/can-master-test
CAN_MASTER_SRCS = tests/rt/can_master_test.c tests/rt/can_selftest.c tests/rt/ramp_check.c
$(CAN_MASTER_TEST): $(CAN_MASTER_SRCS) $(BUILD)/libncpar-can.a tests/rt/ramp_check.h \
                    include/ncpar/can.h include/ncpar/diag.h | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(filter-out -MMD -MP,$(CPPFLAGS)) $(ALL_CFLAGS) -o $@ $(CAN_MASTER_SRCS) \
	    $(BUILD)/libncpar-can.a

test-rt test-can-host: $(CAN_MASTER_TEST) $(BUILD)/cnc-drive-sim
