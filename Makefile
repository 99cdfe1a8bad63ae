# Makefile -- sonard: portable core (src/core), host daemon (src/host), tools, tests. `make help` lists the targets.
BUILD    ?= build
CC       ?= cc
CXX      ?= c++
OPT      ?= -O2
SAN      ?=
ARM_CC   ?= arm-none-eabi-gcc
ARM_SIZE ?= arm-none-eabi-size
ARM_NM   ?= arm-none-eabi-nm
ARM_OBJCOPY ?= arm-none-eabi-objcopy

# The core gets the strict set; host code and tests compile with the same warnings plus POSIX.
WARN      = -std=c99 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Werror -Wcast-qual -Wstrict-prototypes \
            -Wmissing-prototypes -Wundef
CORE_CFLAGS = $(WARN) $(OPT) -g $(SAN) -Iinclude -MMD -MP $(EXTRA_CFLAGS)
HOST_CFLAGS = $(WARN) $(OPT) -g $(SAN) -Iinclude -Isrc/host -Isrc/msg -D_POSIX_C_SOURCE=200809L -MMD -MP $(EXTRA_CFLAGS)
TEST_CFLAGS = $(WARN) $(OPT) -g $(SAN) -Iinclude -Isrc/host -Isrc/msg -D_POSIX_C_SOURCE=200809L -DUNIT_TESTING -MMD -MP $(EXTRA_CFLAGS)
# White-box tests of a module's stages see its private header; no other test does.
WHITEBOX  = detector_stages median
LDLIBS    = -lm
# Sources and objects of a rule: -MMD also lists headers as prerequisites, which clang refuses as inputs.
INPUTS    = $(filter %.c %.cpp %.o %.a,$^)

CORE_SRC  = $(wildcard src/core/*.c)
CORE_OBJ  = $(CORE_SRC:src/core/%.c=$(BUILD)/core/%.o)
HOST_LIB  = src/host/herr.c src/host/csv.c src/host/csv_file.c src/host/optschema.c src/host/options.c src/host/options_check.c src/host/options_values.c src/host/report.c src/host/app.c src/host/app_device.c src/host/app_status.c src/host/app_bg.c src/host/obsmap.c src/host/bgstore.c src/host/survey_run.c src/host/source_replay.c \
            src/host/posefile.c src/host/pvbin.c src/host/discover.c src/host/blueos.c
HOST_OBJ  = $(HOST_LIB:src/host/%.c=$(BUILD)/host/%.o) $(BUILD)/msg/view.o
# The LCM mappings (host and firmware); view.c (the outputs' view, host only, no LCM) goes with the host objects.
MSG_SRC   = $(filter-out src/msg/view.c,$(wildcard src/msg/*.c))
MSG_OBJ   = $(MSG_SRC:src/msg/%.c=$(BUILD)/msg/%.o)
LIVE_OBJ  = $(BUILD)/host/live.o $(BUILD)/host/link.o $(BUILD)/host/source_link.o $(BUILD)/host/sinks.o $(MSG_OBJ) \
            $(BUILD)/host/source_coproc.o $(BUILD)/host/mav.o $(BUILD)/host/mav_rx.o \
            $(BUILD)/host/mav_tx.o $(BUILD)/host/source_pose_lcm.o $(BUILD)/host/control.o
LCM_TYPES = $(wildcard lcm_types/*.lcm)
LCM_NAMES = $(LCM_TYPES:lcm_types/%.lcm=%)
LCM_OBJ   = $(LCM_NAMES:%=$(BUILD)/lcm/c/%.o)
LCM_GEN   = /usr/bin/lcm-gen
UNIT      = ping ping360 device cpframe bgfile survey structure geometry median cfar background sweep kmeans hull detector detector_stages detector_walls detector_edge edge streak tracker tracker_walls clutter activity pose obstacle pipeline csv posefile options discover pvbin optschema scan gain blueos
UNIT_LIVE = app sinks mav source_pose_lcm msg link control
UNIT_BIN  = $(UNIT:%=$(BUILD)/tests/test_%) $(UNIT_LIVE:%=$(BUILD)/tests/test_%)
OPENCV_FLAGS = $(shell pkg-config --cflags --libs opencv4 2>/dev/null)

.PHONY: mcu-property test-stalls test-under-load view-cost ros2-cost cockpit-test fresh-check passive-test blueos blueos-test pi-cost test-arm structure-test survey-test bgfile-test scan-test golden golden-update view view-test mcap deb deb-test discover mcu-demo mcu-unit mcu-bench mcu-test firmware fuzz-coverage fuzz-random soak docs docs-check all deps test unit fuzz check-noheap e2e live realdata crosscheck mavlink spy eval figures opencv-ref asan bench demo cross size clean help venv

# ARCH=armhf|arm64: the host programs cross-built for a Raspberry Pi's Debian into build-ARCH/, against the
# target's LCM and cmocka unpacked into build-ARCH/sysroot (tools/build/arm_sysroot.sh, run when it is missing or
# its recipe changed).
ifneq ($(ARCH),)
TRIPLE_armhf = arm-linux-gnueabihf
TRIPLE_arm64 = aarch64-linux-gnu
TRIPLE := $(TRIPLE_$(ARCH))
ifeq ($(TRIPLE),)
$(error ARCH=$(ARCH): armhf or arm64)
endif
BUILD := build-$(ARCH)
SYSROOT := $(BUILD)/sysroot
ifneq ($(shell cat $(SYSROOT)/.done 2>/dev/null),$(shell cksum < tools/build/arm_sysroot.sh | cut -d' ' -f1))
$(info arm_sysroot: making $(SYSROOT) (missing, or made by another recipe))
$(if $(shell sh tools/build/arm_sysroot.sh $(ARCH) $(SYSROOT) >&2 && echo ok),,$(error tools/build/arm_sysroot.sh $(ARCH) failed))
endif
CC := $(TRIPLE)-gcc
AR := $(TRIPLE)-ar
CROSS_CFLAGS := -isystem $(SYSROOT)/usr/include
EXTRA_CFLAGS += $(CROSS_CFLAGS)
LDLIBS += -L$(SYSROOT)/usr/lib/$(TRIPLE) -Wl,-rpath-link,$(SYSROOT)/usr/lib/$(TRIPLE):$(SYSROOT)/lib/$(TRIPLE)
endif

## all: build build/sonard, build/sonar-sim, build/sonar-feed, build/sonar-pvbin2csv and build/sonar-wallfit (default)
all: $(BUILD)/sonard $(BUILD)/sonar-sim $(BUILD)/sonar-feed $(BUILD)/sonar-pvbin2csv $(BUILD)/sonar-wallfit

## deps: apt-get the packages that are missing (idempotent; needs root or sudo only when something is missing)
deps:
	@sh tools/build/deps.sh

$(BUILD)/core/%.o: src/core/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CORE_CFLAGS) -c $< -o $@

$(BUILD)/host/%.o: src/host/%.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -c $< -o $@

# MAVLink: C headers generated at build time by a pinned pymavlink's mavgen from its ardupilotmega
# dialect (header-only; sonard uses the *_pack_status and frame_char_buffer forms, no globals).
MAVLINK_GEN = $(BUILD)/mavlink/ardupilotmega/mavlink.h
.venv-mavlink/.done: tools/requirements-mavlink.txt
	python3 -m venv .venv-mavlink && .venv-mavlink/bin/pip install -q -r tools/requirements-mavlink.txt && touch $@
$(MAVLINK_GEN): .venv-mavlink/.done
	rm -rf $(BUILD)/mavlink
	@mkdir -p $(BUILD)
	@.venv-mavlink/bin/python -c 'import os, sys, pymavlink; from pymavlink.generator import mavgen; \
	  xml = os.path.join(os.path.dirname(pymavlink.__file__), "dialects", "v20", "ardupilotmega.xml"); \
	  o = mavgen.Opts("$(BUILD)/mavlink", wire_protocol="2.0", language="C", validate=True); \
	  sys.exit(0 if mavgen.mavgen(o, [xml]) else 1)' > $(BUILD)/mavgen.log 2>&1 || { cat $(BUILD)/mavgen.log; exit 1; }
	@test -f $@ && echo "mavgen: $(BUILD)/mavlink from pymavlink $$(.venv-mavlink/bin/python -c 'import importlib.metadata as m; print(m.version("pymavlink"))') (ardupilotmega, MAVLink 2)"
$(BUILD)/host/mav.o $(BUILD)/host/mav_rx.o $(BUILD)/host/mav_tx.o: $(BUILD)/host/%.o: src/host/%.c $(MAVLINK_GEN)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -isystem $(BUILD)/mavlink -c $< -o $@

# LCM types: C (no pubsub: encode only, no heap), Python (log decoding), Java (lcm-spy, `make spy`).
# lcm-gen 1.3.1 exits 0 when it fails to write, so the outputs are checked.
$(BUILD)/lcm/.stamp: $(LCM_TYPES)
	@mkdir -p $(BUILD)/lcm/c $(BUILD)/lcm/python
	$(LCM_GEN) -c --c-no-pubsub --c-cpath $(BUILD)/lcm/c --c-hpath $(BUILD)/lcm/c $(LCM_TYPES)
	$(LCM_GEN) -p --ppath $(BUILD)/lcm/python $(LCM_TYPES)
	@for n in $(LCM_NAMES); do test -f $(BUILD)/lcm/c/$$n.c || { echo "lcm-gen did not write $$n.c"; exit 1; }; done
	@touch $@

$(BUILD)/lcm/c/%.o: $(BUILD)/lcm/.stamp
	$(CC) -std=c99 -O2 -g $(SAN) $(CROSS_CFLAGS) -I$(BUILD)/lcm/c -Wno-pedantic -Wno-unused-parameter -c $(BUILD)/lcm/c/$*.c -o $@

$(BUILD)/host/sinks.o: src/host/sinks.c $(BUILD)/lcm/.stamp
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -I$(BUILD)/lcm/c -Isrc/msg -c $< -o $@

$(BUILD)/host/source_coproc.o: src/host/source_coproc.c $(BUILD)/lcm/.stamp
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -I$(BUILD)/lcm/c -Isrc/msg -c $< -o $@

$(BUILD)/host/source_pose_lcm.o $(BUILD)/host/control.o: $(BUILD)/host/%.o: src/host/%.c $(BUILD)/lcm/.stamp
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -I$(BUILD)/lcm/c -Isrc/msg -c $< -o $@

$(BUILD)/msg/view.o: src/msg/view.c
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -c $< -o $@

$(BUILD)/msg/%.o: src/msg/%.c $(BUILD)/lcm/.stamp
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -I$(BUILD)/lcm/c -Isrc/msg -c $< -o $@

$(BUILD)/libsonarcore.a: $(CORE_OBJ)
	$(AR) rcs $@ $^

# The host library the tools link: each takes only the objects it uses (sonar-sim: the CSV writer and options).
$(BUILD)/libsonarhost.a: $(HOST_OBJ)
	$(AR) rcs $@ $^

$(BUILD)/sonard: $(BUILD)/host/sonard.o $(LIVE_OBJ) $(HOST_OBJ) $(LCM_OBJ) $(BUILD)/libsonarcore.a
	$(CC) $(SAN) $(INPUTS) -o $@ -llcm $(LDLIBS)

FEED_SRC  = $(wildcard tools/sim/feed/*.c)

$(BUILD)/sonar-sim: tools/sim/sonar_sim.c tools/sim/scene.c $(BUILD)/libsonarhost.a $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Wno-conversion $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/sonar-feed: $(FEED_SRC) tools/sim/scene.c $(BUILD)/libsonarhost.a $(BUILD)/libsonarcore.a \
                     $(MAVLINK_GEN)
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itools/sim -isystem $(BUILD)/mavlink -Wno-conversion -Wno-sign-conversion $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/sonar-wallfit: tools/eval/wallfit.c tools/sim/scene.c $(BUILD)/libsonarhost.a $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Itools/sim -Wno-conversion $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/sonar-pvbin2csv: tools/data/pvbin2csv.c $(BUILD)/libsonarhost.a $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(HOST_CFLAGS) -Wno-conversion -Wno-sign-conversion -D_DEFAULT_SOURCE $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/tests/test_%: tests/test_%.c $(HOST_OBJ) $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $(if $(filter $*,$(WHITEBOX)),-Isrc/core) $(INPUTS) -o $@ -lcmocka $(LDLIBS)

# activity.c built again with 4 slots beside the test, so that more tracks than slots (the firmware's case) is reached.
$(BUILD)/tests/test_activity: tests/test_activity.c src/core/activity.c $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) -DSONAR_ACT_SLOTS=4 $^ -o $@ -lcmocka $(LDLIBS)

# The app core and the sinks are tested with the live objects and the generated LCM types.
$(UNIT_LIVE:%=$(BUILD)/tests/test_%): $(BUILD)/tests/test_%: tests/test_%.c $(LIVE_OBJ) $(HOST_OBJ) $(LCM_OBJ) $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) -I$(BUILD)/lcm/c -Isrc/msg -isystem $(BUILD)/mavlink $(INPUTS) -o $@ -lcmocka -llcm $(LDLIBS)

$(BUILD)/tests/test_opencv_ref: tests/test_opencv_ref.cpp $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -O2 -g $(SAN) -Iinclude $(INPUTS) -o $@ $(OPENCV_FLAGS) -lcmocka $(LDLIBS)

## test: install deps, then unit tests, OpenCV reference checks, parser fuzzing, replay and live end-to-end tests, the golden replays, real-data converters, the brping cross-check, check-noheap; builds the benches so they cannot rot
test: deps
	@$(MAKE) --no-print-directory unit docs-check opencv-ref fuzz e2e golden bgfile-test survey-test structure-test live passive-test scan-test mavlink mcap view-test cockpit-test ros2-test discover deb-test soak mcu-test realdata crosscheck check-noheap \
	  $(BUILD)/bench $(BUILD)/bench_opencv

unit: $(UNIT_BIN)
	@set -e; for t in $(UNIT_BIN); do echo "== $$t"; $$t; done

$(BUILD)/tests/fuzz_parser: tests/fuzz_parser.c $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $(INPUTS) -o $@ $(LDLIBS)

## fuzz: the parser-contract harness on random streams (FUZZ_ROUNDS of 1 MiB, default 40), then each libFuzzer harness (Ping parser + Ping360 driver, co-processor frames, CSV, config, .bin, MAVLink in, discovery replies, pose CSV) for FUZZ_SECONDS (default 5) under ASan+UBSan
FUZZ_SECONDS ?= 5
FUZZ_HARNESS = ping360 cpframe csv config pvbin mavlink discover posefile
FUZZ_SAN = -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer
fuzz: fuzz-random
	@$(MAKE) --no-print-directory BUILD=build-fuzz CC=clang OPT=-O1 SAN="$(FUZZ_SAN) -fsanitize=fuzzer-no-link" \
	  $(FUZZ_HARNESS:%=build-fuzz/fuzz/fuzz_%)
	@for h in $(FUZZ_HARNESS); do w=$$(mktemp -d /tmp/sonard-fuzz-$$h.XXXXXX); \
	  echo "== libFuzzer $$h, $(FUZZ_SECONDS) s (seeds tests/fuzz/corpus/$$h)"; \
	  build-fuzz/fuzz/fuzz_$$h -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 -artifact_prefix=$$w/ $$w tests/fuzz/corpus/$$h \
	    > $$w.log 2>&1 || { tail -40 $$w.log; echo "fuzz: $$h FAILED; the input is in $$w/"; exit 1; }; \
	  grep -E "^#[0-9]+.*DONE|stat::number_of_executed_units|cov:" $$w.log | tail -2; rm -rf $$w $$w.log; done

## fuzz-coverage: line, branch and function coverage the corpora reach (FUZZ_CORPUS=DIR, default the seeds), via llvm-cov
fuzz-coverage:
	@sh tools/build/fuzz_coverage.sh $(or $(FUZZ_CORPUS),tests/fuzz/corpus)

## fuzz-random: the parser-contract harness alone (it also runs under make asan)
fuzz-random: $(BUILD)/tests/fuzz_parser
	@$< $(or $(FUZZ_ROUNDS),40)

# The MAVLink harness takes the endpoint's objects and the generated headers.
$(BUILD)/fuzz/fuzz_mavlink: tests/fuzz/fuzz_mavlink.c $(BUILD)/host/mav.o $(BUILD)/host/mav_rx.o $(BUILD)/host/mav_tx.o \
                            $(BUILD)/host/link.o $(HOST_OBJ) $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) -isystem $(BUILD)/mavlink -fsanitize=fuzzer $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/fuzz/fuzz_%: tests/fuzz/fuzz_%.c $(HOST_OBJ) $(BUILD)/libsonarcore.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) -fsanitize=fuzzer $(INPUTS) -o $@ $(LDLIBS)

opencv-ref: $(BUILD)/tests/test_opencv_ref
	@echo "== $<"; $<

$(BUILD)/config_doc: tools/build/config_doc.c $(BUILD)/libsonarhost.a $(BUILD)/libsonarcore.a
	$(CC) $(HOST_CFLAGS) $(INPUTS) -o $@ $(LDLIBS)

## docs: regenerate docs/configuration.md from the option table (src/host/options.c) and docs/sizes.md from sizeof
docs: $(BUILD)/config_doc $(BUILD)/lcm/.stamp
	$(BUILD)/config_doc docs/configuration.md.in > docs/configuration.md
	sh tools/build/sizes.sh $(BUILD) > docs/sizes.md

## docs-check: fail when docs/configuration.md differs from what the option table generates, docs/sizes.md from sizeof, or a header's RAM figure from either
docs-check: $(BUILD)/config_doc $(BUILD)/lcm/.stamp
	@$(BUILD)/config_doc docs/configuration.md.in | diff -u docs/configuration.md - && echo "docs-check: docs/configuration.md matches the option table"
	@sh tools/build/sizes.sh $(BUILD) | diff -u docs/sizes.md - && echo "docs-check: docs/sizes.md matches sizeof on the M7 and this host"
	@python3 tools/build/ram_check.py docs/sizes.md

## e2e: simulate the pool and open-water scenes, replay them, score against the truth
e2e: all
	@sh tests/e2e.sh $(BUILD)

## golden: every scene's and both AquaScan recordings' replay byte-identical to tests/golden.sha256
golden: all
	@sh tests/golden_check.sh $(BUILD)

## golden-update: rewrite tests/golden.sha256 from this build (for a change meant to change the output; say why in its commit)
golden-update: all
	@sh tests/golden_check.sh $(BUILD) --update

## bgfile-test: the recorded background (--background-save / --background-load): an empty pool recorded and loaded, damaged and mismatched files refused by name, a failed save leaving the old file whole
bgfile-test: all
	@sh tests/bgfile.sh $(BUILD)

## survey-test: the site survey: recorded (replay and live) and used on the pool scenes (precision and recall from the second sweep, nothing replayed against itself), each refusal, a survey that no longer fits (another range, a turned mount, another site) and taken back, bad files; without one, static since start; the resolution floor
survey-test: all
	@sh tests/survey.sh $(BUILD)

## structure-test: structure is not an object: the lanes scene under the default, --structure-s and a recorded empty pool; walls reported as structure and never tracked; bad settings
structure-test: all
	@sh tests/structure.sh $(BUILD)

## pi-cost: sonard's share of a Raspberry Pi 4 core at 50 beams/s, from callgrind's instruction count (method in tools/bench/pi_cost.sh)
pi-cost: all
	@command -v valgrind > /dev/null || sh tools/build/deps.sh valgrind
	@sh tools/bench/pi_cost.sh $(BUILD)

## view-cost: the view server's share of a Pi 4 core with the full view and Cockpit's two tiles open (callgrind; ~3 min)
view-cost: all .venv-view/.done
	@command -v valgrind > /dev/null && command -v curl > /dev/null || sh tools/build/deps.sh valgrind curl iproute2
	@sh tools/bench/view_cost.sh $(BUILD)

## ros2-cost: the ROS 2 bridge's share of a Pi 4 core at 50 beams/s against sonard's own (callgrind), and flat out: every LCM message received or counted lost, its RSS flat (~4 min)
ros2-cost: all .venv-ros2/.done
	@command -v valgrind > /dev/null || sh tools/build/deps.sh valgrind iproute2
	@sh tools/bench/ros2_cost.sh $(BUILD)

## test-arm: sonard and its tests cross-built for armhf and arm64 (Raspberry Pi; ARCH=armhf|arm64 builds into build-ARCH/), run under qemu-user: unit tests pass, golden replays byte-identical
test-arm: all
	@sh tests/arm.sh

## test-stalls: the live suites (live mavlink scan-test mcap passive-test view-test cockpit-test; STALL_SUITES) with each one's whole session frozen for 150 ms every 3 s (SIGSTOP/SIGCONT, as a paused VM): all pass
STALL_SUITES ?= live mavlink scan-test mcap passive-test view-test cockpit-test
test-stalls: all .venv-mavlink/.done .venv-mcap/.done .venv-view/.done
	@sh tests/stalls.sh stalls $(STALL_SUITES)

## test-under-load: the live suites three times each while niced busy loops keep both cores busy: all pass
test-under-load: all .venv-mavlink/.done .venv-mcap/.done .venv-view/.done
	@sh tests/stalls.sh load $(STALL_SUITES)

## live: sonar-feed -> sonard over TCP, UDP and a pty, faulty link, auto mode, SIGTERM (loopback only)
live: all
	@sh tests/live.sh $(BUILD)

## scan-test: the scan planner live: --scan sweep and --scan follow side by side on the moving scene (SCAN_SECONDS, default 80), follow under auto_transmit, bad options
SCAN_SECONDS ?= 80
scan-test: all
	@sh tests/scan.sh $(BUILD) $(SCAN_SECONDS)

## mavlink: sonard --mavlink live over loopback UDP, decoded by pinned pymavlink (.venv-mavlink): HEARTBEAT, OBSTACLE_DISTANCE against the simulated walls, OBSTACLE_DISTANCE_3D, poses from sonar-feed's autopilot, junk traffic
mavlink: all .venv-mavlink/.done
	@sh tests/mavlink.sh $(BUILD)

## deb: build $(BUILD)/sonard_VERSION_ARCH.deb: binaries, systemd units, example config, LCM types (Python, jar), docs
deb: all $(BUILD)/lcm/sonar_types.jar
	@sh tools/build/deps.sh dpkg-dev python3-pip
	@$(if $(ARCH),QEMU_LD_PREFIX=$(CURDIR)/$(SYSROOT) STRIP=$(TRIPLE)-strip) sh tools/pkg/deb.sh $(BUILD) $(ARCH)

## fresh-check: the README's commands as a new user runs them, in a minimal Debian bookworm (debootstrap, cached in build/fresh) with a clean clone of HEAD: make demo, make test's first targets, make ARCH=armhf|arm64 with a replay under qemu, make deb installed and run (root)
fresh-check:
	@sh tools/build/fresh_check.sh $(BUILD)

## blueos: the BlueOS extension (tools/pkg/blueos/) for linux/arm/v7, arm64/v8 and amd64 as OCI archives in build/blueos/ (root; buildah, debootstrap, qemu-user)
blueos: all
	@sh tools/pkg/blueos/build.sh

## passive-test: sonard --passive beside a simulated Ping Viewer through a simulated BlueOS bridge: equal to a replay of the driver's beams, nothing sent that moves the head, gain/range changes, pauses, a forgetful bridge, a Ping1D, two drivers
passive-test: all
	@sh tests/passive.sh $(BUILD)

## blueos-test: --sonar blueos against a simulated ping service and bridge; the images' labels as BlueOS reads them; the arm/v7 image's files run (chroot, qemu-user) on a replay and with the simulator, its view as BlueOS's helper finds it
blueos-test: all .venv-view/.done
	@sh tests/blueos.sh $(BUILD)

## deb-test: install the package with dpkg -i (needs root), run it from the installed paths, two sonard@ instances, purge it
deb-test: deb
	@sh tools/build/deps.sh systemd iproute2 passwd
	@sh tests/deb.sh $(BUILD)

## view: the live polar view on http://127.0.0.1:8360/ (VIEW=ADDR:PORT, LCM=URL, PREFIX=P): run it beside sonard
VIEW ?= 127.0.0.1:8360
.venv-view/.done: tools/requirements-view.txt
	python3 -m venv .venv-view && .venv-view/bin/pip install -q -r tools/requirements-view.txt && touch $@
view: all .venv-view/.done
	.venv-view/bin/python tools/view/sonar_view.py --listen $(VIEW) --types $(BUILD)/lcm/python $(if $(LCM),--lcm '$(LCM)') \
	  $(if $(PREFIX),--prefix $(PREFIX))

## view-test: the view in Debian's headless chromium (selenium) against a live simulated sonar
view-test: all .venv-view/.done
	@sh tools/build/deps.sh chromium chromium-driver python3-selenium iproute2
	@sh tests/view.sh $(BUILD)

## ros2: the ROS 2 bridge's venv (.venv-ros2): ROS 2 Kilted's rclpy and message wheels for CPython 3.11 on x86_64, pinned by hash (tools/requirements-ros2.txt); elsewhere, source your own ROS 2 (docs/ros2.md)
ros2: .venv-ros2/.done
.venv-ros2/.done: tools/requirements-ros2.txt
	@sh tools/build/deps.sh python3-venv iproute2
	python3 -m venv .venv-ros2 && .venv-ros2/bin/pip install -q --require-hashes -r tools/requirements-ros2.txt && touch $@

## ros2-test: the bridge against sonard's LCM in a network namespace: a marker and a point per detection at its centroid, the tracks' IDs, a struggle alarm as ERROR on /diagnostics, bad input, the latency
ros2-test: all .venv-ros2/.done
	@sh tests/ros2.sh $(BUILD)

## cockpit-test: sonard in Cockpit: discovery as Cockpit codes it, both widgets in headless chromium, the survey's actions (--control) against a simulated Ping360
cockpit-test: all .venv-view/.done
	@sh tools/build/deps.sh chromium chromium-driver python3-selenium iproute2
	@sh tests/cockpit.sh $(BUILD)

## mcap: tools/data/lcm2mcap round trips (LCM log -> MCAP -> the mcap reader), bad logs, live recording
.venv-mcap/.done: tools/requirements-mcap.txt
	python3 -m venv .venv-mcap && .venv-mcap/bin/pip install -q -r tools/requirements-mcap.txt && touch $@
mcap: all .venv-mcap/.done
	@sh tests/mcap.sh $(BUILD)

## discover: sonard --discover against sonar-feed answering Ping360 discovery on loopback
discover: all
	@sh tests/discover.sh $(BUILD)

## crosscheck: Blue Robotics' own Python client (bluerobotics-ping, in .venv-brping) against sonar-feed over UDP
crosscheck: all .venv-brping/.done
	@sh tests/crosscheck.sh $(BUILD)

.venv-brping/.done:
	python3 -m venv .venv-brping && .venv-brping/bin/pip install -q 'bluerobotics-ping==0.2.5' && touch $@

## realdata: converters and replay on ../shared/data/real (skips, saying why, when it is absent)
realdata: all
	@sh tests/realdata.sh $(BUILD)

## check-noheap: fail if the core objects reference malloc, calloc, realloc or free
check-noheap: $(CORE_OBJ)
	@if nm -u $(CORE_OBJ) | grep -wE 'malloc|calloc|realloc|free'; then \
	  echo "check-noheap: FAILED: the core references the heap"; exit 1; \
	else echo "check-noheap: core objects reference no malloc/calloc/realloc/free"; fi

## asan: the unit and end-to-end tests under AddressSanitizer and UndefinedBehaviorSanitizer
asan:
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" unit opencv-ref fuzz-random e2e live realdata

## soak: sonard live against a faulty sonar-feed flat out for SOAK_BEAMS beams (default 20000; a day of a Ping360 is 3000000): counters, replay equality, RSS and descriptors flat
SOAK_BEAMS ?= 20000
soak: all
	@python3 tools/bench/soak.py $(BUILD) --beams $(SOAK_BEAMS) $(if $(filter-out 20000,$(SOAK_BEAMS)),--interval 5,--interval 0.5)

## demo: a simulated Ping360 (sonar-feed) driven live by sonard, LCM to a log, detections against the truth
demo: deps all
	@sh tools/demo.sh $(BUILD)

## bench: per-stage speed against OpenCV, memcpy and the study's Python pipeline; live sweep time, recovery, CPU, RSS (creates .venv)
bench: deps all $(BUILD)/bench $(BUILD)/bench_opencv venv .venv-mavlink/.done
	@sh tools/bench/bench.sh $(BUILD)

$(BUILD)/bench: tools/bench/bench.c $(BUILD)/libsonarcore.a
	$(CC) $(HOST_CFLAGS) -Wno-conversion $(INPUTS) -o $@ $(LDLIBS)

$(BUILD)/bench_opencv: tools/bench/bench_opencv.cpp
	$(CXX) -std=c++17 -O2 $< -o $@ $(OPENCV_FLAGS)

## eval: docs/results.md and docs/figures: the study's table, SNR/PSNR/CNR, detection scores (simulated, AquaScan)
eval: deps all venv $(BUILD)/bench $(BUILD)/mcu/bench-400x1200.elf
	.venv/bin/python tools/eval/eval.py --build $(BUILD)

## figures: the figure set for any recording: make figures CSV=FILE.csv OUT=DIR [ARGS="--range 20"]
figures: all venv
	@test -n "$(CSV)" -a -n "$(OUT)" || { echo "usage: make figures CSV=FILE.csv OUT=DIR [ARGS='sonard options']"; exit 2; }
	.venv/bin/python tools/eval/figures.py $(CSV) --out $(OUT) -- $(ARGS)

venv: .venv/.done
.venv/.done: tools/requirements.txt
	python3 -m venv .venv && .venv/bin/pip install -q -r tools/requirements.txt && touch $@

ARM_M7  = -mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard
ARM_M4F = -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
ARM_CFLAGS = $(WARN) -Os -ffunction-sections -fdata-sections -Iinclude

# The co-processor firmware for QEMU's mps2-an500 (Cortex-M7): the core, the board, the LCM encoders.
MCU_SRC   = src/mcu/startup.c src/mcu/board_an500.c src/mcu/board_common.c src/mcu/main.c $(MSG_SRC) $(CORE_SRC)
MCU_LCM   = $(LCM_NAMES:%=$(BUILD)/lcm/c/%.c)
MCU_FLAGS = $(ARM_M7) $(MCU_DEFS) -Os -g -ffunction-sections -fdata-sections -Iinclude -Isrc/mcu -Isrc/msg -isystem $(BUILD)/lcm/c -isystem $(BUILD)/mcu/inc

## firmware: build/mcu/sonard-an500.elf and .bin (QEMU mps2-an500), sonard-an500-h743.elf (the same in an STM32H743's banks) and sonard-f405.elf (STM32F405, QEMU netduinoplus2, 200 x 500); the linker fails an overflowing bank, each bank's use is printed, and no image may link the heap (BOARD=f405 is accepted: every board is built)
firmware: $(BUILD)/mcu/sonard-an500.bin $(BUILD)/mcu/sonard-an500-h743.elf $(BUILD)/mcu/sonard-f405.elf
	@for e in $(BUILD)/mcu/sonard-an500.elf $(BUILD)/mcu/sonard-an500-h743.elf $(BUILD)/mcu/sonard-f405.elf; do \
	  if $(ARM_NM) $$e | grep -wE '_?(malloc|calloc|realloc|free|_malloc_r|_sbrk)$$'; then \
	    echo "firmware: FAILED: $$e references the heap"; exit 1; \
	  else echo "firmware: $$e links no malloc, calloc, realloc, free or _sbrk"; fi; done
	@$(ARM_SIZE) $(BUILD)/mcu/sonard-an500.elf
	@sh tools/build/banks.sh $(BUILD)/mcu/sonard-an500-h743.elf src/mcu/h743.ld
	@sh tools/build/banks.sh $(BUILD)/mcu/sonard-f405.elf src/mcu/f405.ld

$(BUILD)/mcu/inc/lcm/lcm_coretypes.h: /usr/include/lcm/lcm_coretypes.h
	@mkdir -p $(dir $@)
	cp $< $@

$(BUILD)/mcu/sonard-an500.elf: $(MCU_SRC) src/mcu/an500.ld src/mcu/board.h $(BUILD)/lcm/.stamp $(BUILD)/mcu/inc/lcm/lcm_coretypes.h
	@mkdir -p $(dir $@)
	$(ARM_CC) $(WARN) $(MCU_FLAGS) -c src/mcu/main.c -o $(BUILD)/mcu/main.o
	$(ARM_CC) $(MCU_FLAGS) -std=c99 -w -c $(MCU_LCM) && mv $(LCM_NAMES:%=%.o) $(BUILD)/mcu/
	$(ARM_CC) $(WARN) $(MCU_FLAGS) -nostartfiles --specs=nano.specs -T src/mcu/an500.ld -Wl,--gc-sections \
	  -Wl,-Map=$(BUILD)/mcu/sonard-an500.map $(filter-out src/mcu/main.c,$(MCU_SRC)) $(BUILD)/mcu/main.o \
	  $(LCM_NAMES:%=$(BUILD)/mcu/%.o) -lm -o $@

# The same objects in the STM32H743's banks (h743.ld), on the same QEMU board.
$(BUILD)/mcu/sonard-an500-h743.elf: $(BUILD)/mcu/sonard-an500.elf src/mcu/h743.ld
	$(ARM_CC) $(WARN) $(MCU_FLAGS) -nostartfiles --specs=nano.specs -T src/mcu/h743.ld -Wl,--gc-sections \
	  -Wl,-Map=$(BUILD)/mcu/sonard-an500-h743.map $(filter-out src/mcu/main.c,$(MCU_SRC)) $(BUILD)/mcu/main.o \
	  $(LCM_NAMES:%=$(BUILD)/mcu/%.o) -lm -o $@

# The STM32F405 (Cortex-M4F) image: 200 angles (2-gradian cells: the Ping360's beam is 2 degrees wide) x 500
# samples, so that the background (100 KB) and the rest fit its 128 KiB SRAM and 64 KiB CCM (docs/coprocessor.md).
F405_GRID  = -DSONAR_MAX_ANGLES=200 -DSONAR_MAX_SAMPLES=500
# 12 tracks and 4 hypotheses (3 alternatives) keep 8 KiB of the CCM spare (32 and 8 would leave under 4 KiB): a pool
# watcher's sonar rarely has more than 12 people in view, and a sweep rarely more than 3 close calls. One wall: the
# co-processor takes no survey, whose lines are the walls (the 16 would cost 240 B of that spare).
F405_LIMITS = -DSONAR_MAX_TRACKS=12 -DSONAR_TRK_HYPOTHESES=4 -DSONAR_TRK_MAX_WALLS=1
F405_FLAGS = $(ARM_M4F) $(F405_GRID) $(F405_LIMITS) $(F405_DEFS) -Os -g -ffunction-sections -fdata-sections -Iinclude -Isrc/mcu -Isrc/msg -isystem $(BUILD)/lcm/c -isystem $(BUILD)/mcu/inc
F405_SRC   = src/mcu/startup.c src/mcu/board_f405.c src/mcu/board_common.c src/mcu/main.c $(MSG_SRC) $(CORE_SRC)
$(BUILD)/mcu/sonard-f405.elf: $(F405_SRC) src/mcu/f405.ld src/mcu/board.h $(BUILD)/lcm/.stamp $(BUILD)/mcu/inc/lcm/lcm_coretypes.h
	@mkdir -p $(BUILD)/mcu/f405
	@for f in $(MCU_LCM); do $(ARM_CC) $(F405_FLAGS) -std=c99 -w -c $$f -o $(BUILD)/mcu/f405/$$(basename $$f .c).o || exit 1; done
	$(ARM_CC) $(WARN) $(F405_FLAGS) -nostartfiles --specs=nano.specs -T src/mcu/f405.ld -Wl,--gc-sections \
	  -Wl,-Map=$(BUILD)/mcu/sonard-f405.map $(F405_SRC) $(LCM_NAMES:%=$(BUILD)/mcu/f405/%.o) -lm -o $@

# The bench image: BENCH_BEAMS x BENCH_N synthetic sweeps through the core, timed in instructions under -icount shift=0.
$(BUILD)/mcu/bench-%.elf: src/mcu/bench_main.c src/mcu/startup.c src/mcu/board_an500.c src/mcu/board_common.c $(CORE_SRC) src/mcu/an500.ld
	@mkdir -p $(dir $@)
	$(ARM_CC) $(WARN) $(MCU_FLAGS) -O2 -Isrc/core -DBENCH_BEAMS=$(word 1,$(subst x, ,$*)) -DBENCH_N=$(word 2,$(subst x, ,$*)) \
	  -nostartfiles --specs=nano.specs -T src/mcu/an500.ld -Wl,--gc-sections $(filter %.c,$^) -lm -o $@

# The core's unit tests on the Cortex-M7: the same test files, CMocka's API from tests/mcu (semihosting output).
MCU_UNIT = ping ping360 device cpframe geometry median cfar background sweep kmeans hull detector detector_stages detector_edge edge streak tracker tracker_walls clutter pose obstacle pipeline scan gain structure
# The core's cases as on the host (plus src/msg/view.c, which test_pipeline reads its world positions through).
$(BUILD)/mcu/test_%.elf: tests/test_%.c tests/mcu/runner.c tests/mcu/cmocka.h src/mcu/startup.c src/mcu/board_an500.c src/mcu/board_common.c $(CORE_SRC) src/msg/view.c src/mcu/an500.ld
	@mkdir -p $(dir $@)
	$(ARM_CC) $(WARN) $(MCU_FLAGS) -O2 -Itests/mcu -Isrc/msg $(if $(filter $*,$(WHITEBOX)),-Isrc/core) -Wl,--defsym=STACK_SIZE=0x20000 \
	  -nostartfiles --specs=nano.specs --specs=nosys.specs -T src/mcu/an500.ld -Wl,--gc-sections $(filter %.c,$^) -lm -o $@

# The same cases on the STM32F405 (QEMU netduinoplus2) at its grid (200 x 500), those that do not assume the default
# grid's 1200 samples (median, background, cfar) or need more than its 192 KiB (ping, cpframe, detector, pipeline).
MCU_UNIT_F405 = ping360 device geometry sweep kmeans hull detector_stages tracker pose obstacle scan gain structure
$(BUILD)/mcu/f405/test_%.elf: tests/test_%.c tests/mcu/runner.c tests/mcu/cmocka.h src/mcu/startup.c src/mcu/board_f405.c src/mcu/board_common.c $(CORE_SRC) src/msg/view.c tests/mcu/f405_test.ld
	@mkdir -p $(dir $@)
	$(ARM_CC) $(WARN) $(ARM_M4F) $(F405_GRID) -O2 -g -ffunction-sections -fdata-sections -Iinclude -Isrc/mcu -Itests/mcu -Isrc/msg \
	  $(if $(filter $*,$(WHITEBOX)),-Isrc/core) -nostartfiles --specs=nano.specs --specs=nosys.specs -T tests/mcu/f405_test.ld \
	  -Wl,--gc-sections $(filter %.c,$^) -lm -o $@

## mcu-demo: the demo's pool detected on the emulated co-processor (QEMU; BOARD=an500, or f405 for the STM32F405), the QEMU command line printed
BOARD ?= an500
mcu-demo: deps all firmware
	@sh tools/mcu_demo.sh $(BUILD) $(BOARD)

## mcu-unit: the core's CMocka cases built for Cortex-M7 and run in qemu-system-arm -M mps2-an500, then those that fit an STM32F405 built for it and run in -M netduinoplus2, with semihosting
mcu-unit: $(MCU_UNIT:%=$(BUILD)/mcu/test_%.elf) $(MCU_UNIT_F405:%=$(BUILD)/mcu/f405/test_%.elf)
	@for e in $(MCU_UNIT:%=$(BUILD)/mcu/test_%.elf); do echo "== $$e"; timeout 300 qemu-system-arm -M mps2-an500 -display none -monitor none -serial null \
	  -semihosting-config enable=on,target=native -kernel $$e || exit 1; done
	@for e in $(MCU_UNIT_F405:%=$(BUILD)/mcu/f405/test_%.elf); do echo "== $$e (STM32F405)"; timeout 300 qemu-system-arm -M netduinoplus2 -display none -monitor none -serial null \
	  -semihosting-config enable=on,target=native -kernel $$e || exit 1; done

## mcu-bench: instructions per beam and per sweep detection on the Cortex-M7 in QEMU (-icount shift=0), at 400x1200, 400x600, 200x600; then on the Cortex-M4F at the STM32F405's grid (200x500; QEMU's mps2-an386, the M4 MPS2 board: the bench's 200 KB of sweeps do not fit the F405's RAM, and instructions do not depend on the board)
mcu-bench: $(BUILD)/mcu/bench-400x1200.elf $(BUILD)/mcu/bench-400x600.elf $(BUILD)/mcu/bench-200x600.elf $(BUILD)/mcu/bench-f405.elf
	@for e in $(filter-out %/bench-f405.elf,$^); do echo "== $$e"; timeout 600 qemu-system-arm -M mps2-an500 -display none -monitor none -icount shift=0 \
	  -semihosting-config enable=on,target=native -kernel $$e -serial stdio -serial null || exit 1; done
	@echo "== $(BUILD)/mcu/bench-f405.elf (Cortex-M4F, 200 x 500)"; timeout 600 qemu-system-arm -M mps2-an386 -display none -monitor none \
	  -icount shift=0 -semihosting-config enable=on,target=native -kernel $(BUILD)/mcu/bench-f405.elf -serial stdio -serial null

$(BUILD)/mcu/bench-f405.elf: src/mcu/bench_main.c src/mcu/startup.c src/mcu/board_an500.c src/mcu/board_common.c $(CORE_SRC) src/mcu/an500.ld
	@mkdir -p $(dir $@)
	$(ARM_CC) $(WARN) $(ARM_M4F) $(F405_GRID) -O2 -g -ffunction-sections -fdata-sections -Iinclude -Isrc/mcu -Isrc/msg -Isrc/core \
	  -DBENCH_BEAMS=200 -DBENCH_N=500 -nostartfiles --specs=nano.specs -T src/mcu/an500.ld -Wl,--gc-sections $(filter %.c,$^) -lm -o $@

$(BUILD)/mcu/sonard-an500.bin: $(BUILD)/mcu/sonard-an500.elf
	$(ARM_OBJCOPY) -O binary $< $@

## mcu-test: the core's unit cases on the Cortex-M7 in QEMU, then the firmware between sonar-feed (UART0) and sonard --coprocessor (UART1): detections equal --replay, a faulty sonar recovered, issue 50's served beams on every board, then MCU_CASES of the property cases
mcu-test: all firmware
	@if command -v qemu-system-arm >/dev/null 2>&1; then $(MAKE) --no-print-directory mcu-unit; \
	else echo "mcu-unit: SKIPPED: qemu-system-arm is not installed (make deps installs it)"; fi
	@sh tests/mcu.sh $(BUILD)
	@sh tests/mcu_property.sh $(BUILD) $(MCU_CASES) 2

## mcu-property: each board against the host on the same beams over generated cases (the simulator's pools and seeds, 1- and 2-gradian steps, 500 and 600 samples, default options, --min-points 10, the preset): MCU_CASES of them (default 8, as make test runs; every combination is 180 a board, 540 in all)
MCU_CASES ?= 8
mcu-property: all firmware
	@sh tests/mcu_property.sh $(BUILD) $(MCU_CASES) 2

## cross: build the core with arm-none-eabi-gcc for Cortex-M7 and Cortex-M4F (-Os)
cross:
	@mkdir -p $(BUILD)/arm-m7 $(BUILD)/arm-m4f
	@for f in $(CORE_SRC); do b=$$(basename $$f .c); \
	  $(ARM_CC) $(ARM_CFLAGS) $(ARM_M7) -c $$f -o $(BUILD)/arm-m7/$$b.o || exit 1; \
	  $(ARM_CC) $(ARM_CFLAGS) $(ARM_M4F) -c $$f -o $(BUILD)/arm-m4f/$$b.o || exit 1; done
	@echo "cross: core built for Cortex-M7 and Cortex-M4F"

## size: link a minimal firmware image holding one pipeline; print flash and static RAM (400x1200, 400x600, M4F 200x600)
size: cross
	@sh tools/build/size.sh $(BUILD)

## spy: build the Java LCM types and open lcm-spy on them (installs liblcm-java, jchart2d, a JDK if missing)
spy: $(BUILD)/lcm/sonar_types.jar
	@echo "lcm-spy on $${LCM_DEFAULT_URL:-LCM's default URL}; types from $<"
	CLASSPATH=$< JDK_JAVA_OPTIONS=-XX:+IgnoreUnrecognizedVMOptions lcm-spy

# Debian's lcm-spy wrapper passes -Xincgc (rejected since Java 9: IgnoreUnrecognizedVMOptions) and
# needs jchart2d, which liblcm-java does not pull in.
$(BUILD)/lcm/sonar_types.jar: $(LCM_TYPES)
	@sh tools/build/deps.sh liblcm-java libjchart2d-java default-jdk-headless liblcm-bin
	@rm -rf $(BUILD)/lcm/java $(BUILD)/lcm/jclasses && mkdir -p $(BUILD)/lcm/java $(BUILD)/lcm/jclasses
	$(LCM_GEN) -j --jpath $(BUILD)/lcm/java $(LCM_TYPES)
	javac -nowarn -cp /usr/share/java/lcm.jar -d $(BUILD)/lcm/jclasses $(BUILD)/lcm/java/sonar/*.java
	jar cf $@ -C $(BUILD)/lcm/jclasses .

## clean: remove build outputs
clean:
	rm -rf $(BUILD) build-asan build-clang build-fuzz build-fuzzcov build-dev build-mcu-* build-armhf build-arm64 .venv .venv-brping .venv-mavlink

## help: this list
help:
	@grep -E '^## ' Makefile | sed 's/^## /  /'

-include $(wildcard $(BUILD)/*/*.d)
