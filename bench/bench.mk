# `make bench`: the benchmark suite of bench/ (not part of `make test`). It
# reproduces the interpreter-pipeline paper's Table 3, compares with LinuxCNC's
# rs274 and measures the position loop's latency beside cyclictest, runs the
# timing-faults paper's circle under timing faults (bench/seed003), measures the
# distributed NCK's messages and accuracy (bench/dist, the distributed-NCK
# paper's Tables I-IV) and the task-scheduling paper's task chain under both
# scheduling strategies (bench/seed000), then rewrites its sections of
# bench/RESULTS.md and the PNGs in bench/. RUNS, RUNS_BIG, LAT_SECONDS, ... scale it down (bench/run-bench).
.PHONY: bench
# Every program in bench/: `make` (all, what CI builds) builds them too, so that a
# change of the library's API cannot leave one of them unbuildable until the
# next `make bench`.
BENCH_BINS = $(patsubst bench/%.c,$(BUILD)/bench/%,$(wildcard bench/*.c))
all: $(BENCH_BINS)

$(BUILD)/bench/%: bench/%.c $(LIB) | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -o $@ $< $(LIB) $(LDLIBS) -lstdc++

bench: all $(BENCH_BINS)
	bench/run-bench $(BUILD)

# The service benchmark's client speaks LCM through liblcm, as any client would.
$(BUILD)/bench/service-bench: bench/service-bench.c $(LIB) | $(GEN_STAMP)
	@mkdir -p $(@D)
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -o $@ $< $(LIB) -llcm $(LDLIBS)

bench-service: all $(BUILD)/bench/service-bench
	bench/bench-service $(BUILD)
.PHONY: bench-service

# Time and memory of `parse` at 10^6 and 10^7 blocks (SCALE_MAX=8: 10^8 too,
# ~10 GB of disk for the program and its output, and minutes).
SCALE_MAX ?= 7
bench-scale: all
	bench/scale $(BUILD) $(SCALE_MAX)
.PHONY: bench-scale
