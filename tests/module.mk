# SPDX-License-Identifier: ISC
# tests: unit tests (cmocka, one program per tests/unit/test_*.c), system tests
# (tests/system/NNN-*.sh against the real binaries), libFuzzer targets, benchmarks.
UNIT_SRC   := $(wildcard tests/unit/test_*.c)
UNIT_BINS  := $(patsubst tests/unit/%.c,$(BUILD)/tests/%,$(UNIT_SRC))
UNIT_HELP  := $(wildcard tests/unit/helpers/*.c)
SYS_TESTS  := $(sort $(wildcard tests/system/[0-9]*.sh))
BENCH_SRC  := $(wildcard tests/bench/bench_*.c)
BENCH_BINS := $(patsubst tests/bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))
TEST_LIBS   = $(LIBPSD_CORE)
# the tests of a room link its library too
ROOM_TESTS_REPORT = $(BUILD)/tests/test_report $(BUILD)/tests/test_chart
ROOM_TESTS_PSVIRT = $(BUILD)/tests/test_mbframe $(BUILD)/tests/test_mbpdu $(BUILD)/tests/test_dalibus

$(UNIT_BINS): $(BUILD)/tests/%: $(BUILD)/obj/tests/unit/%.o $(call obj,$(UNIT_HELP)) $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(LINK) -lcmocka
$(ROOM_TESTS_REPORT): $(LIBPSDREPORT)
$(ROOM_TESTS_PSVIRT): $(LIBPSVIRT)

$(BENCH_BINS): $(BUILD)/bench/%: $(BUILD)/obj/tests/bench/%.o $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(LINK)

tests: all $(UNIT_BINS) $(TEST_EXTRA)

# The README's test command.  Installs missing Debian packages (as root), builds
# everything, then runs every unit and system test; ends with "N passed, N failed".
check: deps-peers
	$(MAKE) tests
	@# '+': some tests run make themselves (091 runs make run): they share
	@# this make's jobserver instead of warning that it is unavailable
	+BUILD=$(BUILD) BIN=$(BUILD)/bin TOP=$(CURDIR) sh tests/run.sh -j $(CHECK_JOBS) $(UNIT_BINS) $(SYS_TESTS)
# tests at once: most system tests wait on sockets and clocks, so twice the
# cores keeps the machine busy; CHECK_JOBS=1 runs them one after another
CHECK_JOBS ?= $(shell echo $$(( $$(nproc) * 2 )))

bench: all $(BENCH_BINS)
	@for b in $(BENCH_BINS); do echo "== $$b"; BUILD=$(BUILD) $$b || exit 1; done
	@for s in $(wildcard tests/bench/*.sh); do echo "== $$s"; BUILD=$(BUILD) BIN=$(BUILD)/bin sh $$s || exit 1; done
	@echo "== the fuzz targets, up to $(BENCH_FUZZ_TIME) s each$(if $(filter-out 0,$(BENCH_FUZZ_RUNS)), or $(BENCH_FUZZ_RUNS) executions): executions without a crash"
	@$(MAKE) --no-print-directory fuzz FUZZ_TIME=$(BENCH_FUZZ_TIME) FUZZ_RUNS=$(BENCH_FUZZ_RUNS) > $(BUILD)/bench-fuzz.log 2>&1; rc=$$?; \
	    grep -E '^(target|fuzz_|total)|CRASH' $(BUILD)/bench-fuzz.log; exit $$rc
# The long run: make bench BENCH_FUZZ_RUNS=1000000 BENCH_FUZZ_TIME=900 (every
# target to 1e6 executions, failing one that does not get there in 900 s).
BENCH_FUZZ_TIME ?= 10
BENCH_FUZZ_RUNS ?= 0

# The soak (tests/soak/soak.sh): psensd at 600x for SOAK_SECONDS (600) under
# faults, 50 socket clients, reloads and a slow module; descriptors and
# resident memory at start and end.  Not part of check.
# Then the sample log's soak (tests/soak/logsoak.sh): SOAK_LOG_SECONDS (600)
# at 600x with MQTT, a database lock, a full disk (as root) or a kill -9
# every 30 s; samples logged, published, dropped and lost counted.
SOAK_SECONDS ?= 600
SOAK_LOG_SECONDS ?= 600
.PHONY: soak
soak: all
	BUILD=$(BUILD) BIN=$(BUILD)/bin SOAK_SECONDS=$(SOAK_SECONDS) sh tests/soak/soak.sh
	BUILD=$(BUILD) BIN=$(BUILD)/bin SOAK_LOG_SECONDS=$(SOAK_LOG_SECONDS) sh tests/soak/logsoak.sh

# libFuzzer targets: tests/fuzz/fuzz_*.c, built with clang into $(BUILD)-fuzz,
# each run for FUZZ_TIME seconds from its seeds in tests/fuzz/seeds/<name>/,
# or until FUZZ_RUNS executions when that is given (then falling short of it
# in FUZZ_TIME fails): make fuzz FUZZ_RUNS=1000000 FUZZ_TIME=900
FUZZ_SRC    := $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_TIME   ?= 60
FUZZ_RUNS   ?= 0
FUZZ_BUILD   = $(BUILD)-fuzz
fuzz:
	$(MAKE) BUILD=$(FUZZ_BUILD) CC=clang OPT="-O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all" \
	    LDFLAGS="-fsanitize=address,undefined" fuzz-bins
	CORPUS=$(FUZZ_BUILD)/corpus RUNS=$(FUZZ_RUNS) sh tests/fuzz/run.sh $(FUZZ_TIME) $(patsubst tests/fuzz/%.c,$(FUZZ_BUILD)/fuzz/%,$(FUZZ_SRC))
FUZZ_BINS = $(patsubst tests/fuzz/%.c,$(BUILD)/fuzz/%,$(FUZZ_SRC))
fuzz-bins: $(FUZZ_BINS)
$(FUZZ_BINS): $(BUILD)/fuzz/%: $(BUILD)/obj/tests/fuzz/%.o $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -fsanitize=fuzzer,address,undefined -o $@ $(filter-out %.a,$^) \
	    -Wl,--start-group $(filter %.a,$^) -Wl,--end-group $(LIBS)
$(BUILD)/fuzz/fuzz_mbframe $(BUILD)/fuzz/fuzz_dalibus: $(LIBPSVIRT)
-include tests/emu/module.mk

# The daemon's system tests once under valgrind (memcheck, leaks, descriptors
# left open): tests/valgrind.sh.  The load, kill and 3600x Modbus tests are
# timing tests and stay out (valgrind runs 20-50 times slower).
VALGRIND_TESTS := $(wildcard tests/system/200-*.sh tests/system/210-*.sh tests/system/220-*.sh \
                  tests/system/230-*.sh tests/system/245-*.sh tests/system/246-*.sh \
                  tests/system/410-*.sh tests/system/415-*.sh tests/system/430-*.sh)
.PHONY: check-valgrind
check-valgrind: deps
	$(MAKE) tests
	BUILD=$(BUILD) BIN=$(BUILD)/bin TOP=$(CURDIR) sh tests/valgrind.sh $(VALGRIND_TESTS)

# dali-serial (tests/system/peers/daliserial.c): the serial DALI link
# against the bus emulator tests/system/peers/dalibus.py (tests/system/417).
$(BUILD)/tests/dali-serial: $(BUILD)/obj/tests/system/peers/daliserial.o $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(LINK)
tests: $(BUILD)/tests/dali-serial
