# ncpar: one non-recursive Makefile, per-module fragments in src/*/module.mk.
# `make V=1` shows the commands. Everything is built out of tree in build/.

BUILD    ?= build
CC       ?= gcc
CXX      ?= g++
# Link-time optimisation: the ring and stage calls the pipeline makes per
# block cross files (ring.c, stages.c, lex, analyzer), and only LTO inlines
# them into the analyzer thread's loop. Measure what it buys with
# `make bench-parse` built with and without it (bench/RESULTS.md,
# "Interpreter throughput", records the machine and date of a run).
CFLAGS   ?= -O2 -g -flto=auto
CXXFLAGS ?= -O2 -g -flto=auto
# gcc-ar: an archive of LTO objects needs the linker plugin's symbol index
AR       := $(if $(findstring -flto,$(CFLAGS)),gcc-ar,ar)
WARN      = -Wall -Wextra -Werror
CPPFLAGS += -Iinclude -I$(BUILD)/gen -D_GNU_SOURCE -MMD -MP
ALL_CFLAGS   = -std=c11 $(WARN) $(CFLAGS) -pthread
ALL_CXXFLAGS = -std=c++17 $(WARN) $(CXXFLAGS) -pthread -fno-exceptions -fno-rtti \
               -I/usr/include/eigen3
# libcrypto: the MAC on every LCM message (src/auth); -ldl for its static archive
LDLIBS   += -lm -linih -lcrypto -ldl -pthread
# cnc-run itself is linked statically: the dynamic loader's mapping and
# relocating of libstdc++, libm and libc is paid at every start (a page fault
# for each page it touches, dearer still under shadow paging in a VM), which
# short programs and the start-up floor of bench/RESULTS.md ("Against
# LinuxCNC") feel most. Sanitizer builds cannot be static; `make CLI_LDFLAGS=`
# links it dynamically.
CLI_LDFLAGS ?= -static

ifeq ($(V),1)
Q =
else
Q = @
endif

# The C of the LCM message types (lcm/*.lcm) is generated at build time into
# $(BUILD)/gen/ (never committed) and compiled into the library. Every object
# waits for it (order-only on the stamp): any source may include the
# generated headers through include/ncpar/msg.h, and a fresh build has no .d
# files yet to say which do. A changed .lcm regenerates, and the .d files
# then rebuild whatever included the headers.
GEN_DIR   = $(BUILD)/gen
GEN_STAMP = $(GEN_DIR)/.stamp
LCM_TYPES := $(wildcard lcm/*.lcm)
GEN_SRCS  = $(LCM_TYPES:lcm/%.lcm=$(GEN_DIR)/%.c)
GEN_OBJS  = $(GEN_SRCS:%.c=%.o)

LIB_SRCS :=
LIB_CXXSRCS :=
include $(wildcard src/*/module.mk)

LIB_OBJS = $(LIB_SRCS:%.c=$(BUILD)/%.o) $(LIB_CXXSRCS:%.cpp=$(BUILD)/%.o) $(GEN_OBJS)
LIB      = $(BUILD)/libncpar.a
CLI_SRCS = $(wildcard src/cli/*.c)
CLI_OBJS = $(CLI_SRCS:%.c=$(BUILD)/%.o)

UNIT_SRCS = $(wildcard tests/unit/test_*.c)
UNIT_BINS = $(UNIT_SRCS:tests/unit/%.c=$(BUILD)/tests/%)

.PHONY: all deps test unit clean sanitize fuzz bench-parse
all: $(BUILD)/cnc-run $(LIB)

$(LIB): $(LIB_OBJS)
	@mkdir -p $(@D)
	$(Q)rm -f $@ && $(AR) rcs $@ $^

$(BUILD)/cnc-run: $(CLI_OBJS) $(LIB)
	$(Q)$(CXX) $(ALL_CXXFLAGS) $(CLI_LDFLAGS) -o $@ $(CLI_OBJS) $(LIB) $(HTTP_LDLIBS) $(LDLIBS)

# lcm-gen names each file after package and type (ncp_command_t.{c,h}), as
# the .lcm files are named. It skips files newer than their .lcm, so the
# stamp is touched on its own.
$(GEN_STAMP): $(LCM_TYPES)
	@mkdir -p $(@D)
	@$(if $(Q),echo "  GEN  $(GEN_DIR)/ ($(notdir $(LCM_TYPES)))")
	$(Q)lcm-gen -c --c-no-pubsub --c-cpath $(GEN_DIR) --c-hpath $(GEN_DIR) $(LCM_TYPES)
	$(Q)touch $@
$(GEN_SRCS): $(GEN_STAMP) ;

# lcm-gen's code has unused parameters (its decode_cleanup functions). Its
# decoders store a double's bytes through an int64_t pointer (lcm_coretypes.h),
# which strict aliasing lets the compiler ignore: inlined by LTO into a caller
# that had zeroed the message, the doubles came back 0. So these objects are
# compiled without strict aliasing and kept out of LTO (nothing inlines them).
$(GEN_DIR)/%.o: $(GEN_DIR)/%.c | $(GEN_STAMP)
	@$(if $(Q),echo "  CC   $<")
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -fno-strict-aliasing -fno-lto -Wno-unused-parameter -c -o $@ $<

$(BUILD)/%.o: %.c | $(GEN_STAMP)
	@mkdir -p $(@D)
	@$(if $(Q),echo "  CC   $<")
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -c -o $@ $<

$(BUILD)/%.o: %.cpp | $(GEN_STAMP)
	@mkdir -p $(@D)
	@$(if $(Q),echo "  CXX  $<")
	$(Q)$(CXX) $(CPPFLAGS) $(ALL_CXXFLAGS) -c -o $@ $<

$(BUILD)/tests/%: tests/unit/%.c $(LIB) | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -o $@ $< $(LIB) $(LDLIBS) -lcmocka -lstdc++

# The ring's sleep protocol with a test hook compiled in (see the test's header):
# its own copy of ring.c, not the library's.
$(BUILD)/tests/test_ring_race: tests/unit/test_ring_race.c src/pipeline/ring.c $(LIB) | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -DNCP_RING_TEST_HOOKS -o $@ $< src/pipeline/ring.c \
	    $(LIB) $(LDLIBS) -lcmocka

unit: $(UNIT_BINS)

# --version of every binary (tools/version: git describe, or a tarball's
# release). Rewritten only when the version changes, so a new commit
# recompiles the four main files, not the tree.
VERSION_H = $(GEN_DIR)/ncp_version.h
$(VERSION_H): FORCE
	@mkdir -p $(@D)
	$(Q)printf '#define NCP_VERSION "%s"\n' "$$(tools/version)" >$@.tmp && \
	    if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi
$(BUILD)/src/cli/cnc_run.o $(BUILD)/src/ctl/cnc_ctl.o $(BUILD)/src/axis/cnc_axis.o \
    $(BUILD)/src/can-drive-sim/cnc_drive_sim.o: $(VERSION_H)

# libFuzzer targets, tests/fuzz/fuzz_NAME.c, each run FUZZ_SECONDS by `make fuzz`
# from its seeds FUZZ_SEEDS_NAME (none: an empty corpus). Adding a target is a
# line here (and its seeds, if it has any).
FUZZ_TARGETS = pipeline http command
FUZZ_SEEDS_pipeline = ncprograms/*.ngc tests/bad/*.ngc
FUZZ_SEEDS_http = tests/fuzz/seeds-http/*
FUZZ_SEEDS_command = tests/fuzz/seeds-command/*

# Each fuzz target as a plain program (tests/fuzz/replay.c): `make` compiles and
# links them, so an API change that breaks one stops the build, not `make fuzz`
# later. fuzz-replay is the pipeline's, fuzz-replay-NAME another target's.
FUZZ_REPLAY = $(BUILD)/tests/fuzz-replay \
              $(patsubst %,$(BUILD)/tests/fuzz-replay-%,$(filter-out pipeline,$(FUZZ_TARGETS)))
all: $(FUZZ_REPLAY)
$(BUILD)/tests/fuzz-replay: $(BUILD)/tests/fuzz-replay-pipeline
	$(Q)cp $< $@
$(BUILD)/tests/fuzz-replay-%: tests/fuzz/replay.c tests/fuzz/fuzz_%.c $(LIB)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -o $@ tests/fuzz/replay.c tests/fuzz/fuzz_$*.c \
	    $(LIB) $(LDLIBS) -lstdc++

# Build and test dependencies on Debian 12 (run as root).
deps:
	apt-get update -qq
	DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
	    gcc g++ make clang libeigen3-dev libcmocka-dev libinih-dev libssl-dev linuxcnc-uspace \
	    liblcm-dev liblcm-bin \
	    python3 python3-matplotlib python3-scipy valgrind cppcheck clang-tidy file podman \
	    libwebsockets-dev chromium firefox-esr \
	    debhelper lintian man-db curl debootstrap strace
	command -v npm >/dev/null || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	    --no-install-recommends nodejs npm
	tools/rtvm/install-deps
	$(MAKE) web-deps

test: all unit test-can-host
	$(Q)tests/run-tests $(BUILD)

clean:
	rm -rf $(BUILD)

include tools/rtvm/rtvm.mk
include bench/bench.mk
include web/web.mk
include docs/man/man.mk
include deploy/install.mk

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)

# ---- sanitizers, fuzzing, benchmarks --------------------------------------
SAN_FLAGS = -O1 -g -fno-omit-frame-pointer
# ASan+UBSan over the whole test suite; TSan over the parallel equivalence tests,
# the service and the distributed NCK's suites.
# The instrumented binary runs about 7x slower (the runaway-loop cases of
# tests/robust: 2.2 s -> 14.5 s), so a run may take 5x the usual 20 s.
sanitize: all
	RUN_TIMEOUT=100 $(MAKE) BUILD=build-asan CC=clang CXX=clang++ CLI_LDFLAGS= \
	    CFLAGS="$(SAN_FLAGS) -fsanitize=address,undefined -fno-sanitize-recover=all" \
	    CXXFLAGS="$(SAN_FLAGS) -fsanitize=address,undefined -fno-sanitize-recover=all" \
	    LDLIBS="-lm -linih -lcrypto -pthread -fsanitize=address,undefined" test
	$(MAKE) BUILD=build-tsan CC=clang CXX=clang++ CLI_LDFLAGS= \
	    CFLAGS="$(SAN_FLAGS) -fsanitize=thread" CXXFLAGS="$(SAN_FLAGS) -fsanitize=thread" \
	    LDLIBS="-lm -linih -lcrypto -pthread -fsanitize=thread" all build-tsan/tests/test_nck_service
	TSAN_OPTIONS=halt_on_error=1 tests/tools/equivalence --bin build-tsan/cnc-run ncprograms/*.ngc
	TSAN_OPTIONS=halt_on_error=1 build-tsan/tests/test_nck_service
	# the serving NCK under TSan, driven by the plain cnc-ctl (liblcm's glib is not
	# instrumented, so an instrumented cnc-ctl reports glib's own locking)
	mkdir -p build-tsan/service-bin && cp build-tsan/cnc-run $(BUILD)/cnc-ctl build-tsan/service-bin/
	TSAN_OPTIONS=halt_on_error=1 tests/service/run build-tsan/service-bin build-tsan/service-work \
	    | tee build-tsan/service.log
	! grep -q '^FAIL' build-tsan/service.log
	# the distributed NCK under TSan: the HLC's and the LLCs' threads (the
	# position loop, LCM's receive thread, the clock probes); a race report
	# exits 66, which the suite reports as a failed case
	TSAN_OPTIONS="halt_on_error=1 exitcode=66" tests/dist/run build-tsan build-tsan/dist-work \
	    | tee build-tsan/dist.log
	! grep -q '^FAIL' build-tsan/dist.log

# `make fuzz`: every target of FUZZ_TARGETS in turn, FUZZ_SECONDS each (`make fuzz
# FUZZ_SECONDS=60`); `make fuzz-NAME` one of them. The library is built once,
# instrumented, in $(BUILD)-fuzz; each target keeps its corpus there.
FUZZ_SECONDS ?= 60
FUZZ_FLAGS = -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all
$(BUILD)-fuzz/libncpar.a: FORCE
	$(MAKE) BUILD=$(BUILD)-fuzz CC=clang CXX=clang++ \
	    CFLAGS="$(FUZZ_FLAGS) -fsanitize=fuzzer-no-link" \
	    CXXFLAGS="$(FUZZ_FLAGS) -fsanitize=fuzzer-no-link" $(BUILD)-fuzz/libncpar.a
$(BUILD)-fuzz/fuzz_%: tests/fuzz/fuzz_%.c $(BUILD)-fuzz/libncpar.a
	clang $(filter-out -I$(BUILD)/gen,$(CPPFLAGS)) -I$(BUILD)-fuzz/gen -std=c11 $(FUZZ_FLAGS) \
	    -fsanitize=fuzzer -pthread -o $@ $< \
	    $(BUILD)-fuzz/libncpar.a -lm -linih -lcrypto -lstdc++
# the targets are kept for reruns and replays, not removed as intermediates
.PRECIOUS: $(BUILD)-fuzz/fuzz_%
fuzz:
	$(foreach t,$(FUZZ_TARGETS),$(MAKE) fuzz-$(t) &&) true
fuzz-%: $(BUILD)-fuzz/fuzz_%
	mkdir -p $(BUILD)-fuzz/corpus-$*
	$(if $(FUZZ_SEEDS_$*),cp $(FUZZ_SEEDS_$*) $(BUILD)-fuzz/corpus-$*/ 2>/dev/null || true)
	$< -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
	    $(BUILD)-fuzz/corpus-$*

bench-parse: all $(BUILD)/bench/core-latency $(BUILD)/bench/cpu-speed
	bench/bench-parse $(BUILD)

.PHONY: FORCE
FORCE:

# Layering (tests/tools/call-layers): in every folder of src/ the calls
# between files, a header's inline functions included, form no cycle (the
# run loop calls the handlers, the handlers the ground floor, nothing calls
# back up). And no file of src/ reaches another module's private header by a
# ../ path.
lint: lint-layers
lint-layers:
	$(Q)tests/tools/call-layers-test
	$(Q)tests/tools/call-layers $(wildcard src/*/) >/dev/null
	$(Q)! grep -rn '#include *"\.\./' src || { echo "src/: a private header of another module included by ../ path"; exit 1; }
.PHONY: lint-layers

# Static analysis: both must stay quiet on our sources (not on lcm-gen's
# code in $(GEN_DIR), which is in neither list; its headers are only read).
LINT_JOBS ?= 2
lint: $(GEN_STAMP)
	cppcheck --quiet --error-exitcode=1 --enable=warning,style,performance,portability \
	    --inline-suppr --suppress=missingIncludeSystem -Iinclude -I$(GEN_DIR) -D_GNU_SOURCE \
	    --std=c11 src tests/unit
	@# one file a process: clang-tidy's analyzer, given many files in one run,
	@# carries state from one to the next (a va_list "uninitialized" in a
	@# function of another file)
	printf '%s\n' $(LIB_SRCS) $(CLI_SRCS) $(CTL_SRCS) $(AXIS_SRCS) | \
	    xargs -P $(LINT_JOBS) -I{} clang-tidy --quiet {} -- $(CPPFLAGS) -std=c11 -I/usr/include/eigen3
.PHONY: lint

# ---- container image (deploy/Containerfile) ------------------------------------
# The build context is staged: the static cnc-run and the shipped INIs and
# programs, nothing of the source tree's build folders. PODMAN_FLAGS passes
# e.g. --storage-driver vfs where overlay is not available.
PODMAN       ?= podman
PODMAN_FLAGS ?=
IMAGE        ?= localhost/ncpar:latest
IMAGE_CTX     = $(BUILD)/image
image: $(BUILD)/cnc-run
	@if ! file -L $< | grep -q 'statically linked'; then \
	    echo "$<: not statically linked (CLI_LDFLAGS=$(CLI_LDFLAGS)): the image has no libc"; exit 1; fi
	rm -rf $(IMAGE_CTX) && mkdir -p $(IMAGE_CTX)/bin
	cp $< $(IMAGE_CTX)/bin/cnc-run
	cp -r rt-config ncprograms $(IMAGE_CTX)/
	$(PODMAN) $(PODMAN_FLAGS) build --pull=never -f deploy/Containerfile -t $(IMAGE) $(IMAGE_CTX)
.PHONY: image
