# SPDX-License-Identifier: ISC
# tests/emu: the emulated DALI USB interface (libumockdev + real libusb) for the
# DALI driver's tests.  Built only when the driver is (libusb) and umockdev is
# there; the tests that need it skip otherwise.
#   libpsemu.a         the emulator: vusb.c (usbfs on umockdev) + dali_emu.c (interface, ballasts)
#   tests/psemu-run    a parent that hosts the emulator and runs a program, whose
#                      real libusb reaches it from the child (doc/emulation.md 2.4)
#   tests/dali-client  a small program driving the dali_usb driver, for system tests
UMOCK_FOUND := $(shell $(PKG) --exists umockdev-1.0 && echo yes)
ifeq ($(HAVE_USB)$(UMOCK_FOUND),yesyes)
EMU_CFLAGS := $(patsubst -I%,-isystem %,$(shell $(PKG) --cflags umockdev-1.0)) -DPS_WITH_UMOCKDEV
EMU_LIBS   := $(shell $(PKG) --libs umockdev-1.0)
LIBPSEMU   := $(BUILD)/lib/libpsemu.a
EMU_UNIT   := $(BUILD)/tests/test_dali_usb $(BUILD)/tests/test_dali_commission

$(BUILD)/obj/tests/emu/%.o: CFLAGS += $(EMU_CFLAGS)
$(patsubst $(BUILD)/tests/%,$(BUILD)/obj/tests/unit/%.o,$(EMU_UNIT)): CFLAGS += $(EMU_CFLAGS) -Itests/emu

$(LIBPSEMU): $(call obj,tests/emu/vusb.c tests/emu/dali_emu.c)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(EMU_UNIT): $(LIBPSEMU)
$(EMU_UNIT): LIBS += $(LIBPSEMU) $(EMU_LIBS)

# the commissioning bench runs on the emulator too (tests/bench)
EMU_BENCH := $(BUILD)/bench/bench_dali_commission
$(BUILD)/obj/tests/bench/bench_dali_commission.o: CFLAGS += $(EMU_CFLAGS) -Itests/emu -Itests/unit
$(EMU_BENCH): $(LIBPSEMU) $(call obj,tests/unit/helpers/dali_preload.c)
$(EMU_BENCH): LIBS += $(LIBPSEMU) $(EMU_LIBS)

$(BUILD)/tests/psemu-run: $(BUILD)/obj/tests/emu/psemu_run.o $(LIBPSEMU)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) -o $@ $^ $(EMU_LIBS) $(LIBS)

$(BUILD)/tests/dali-client: $(BUILD)/obj/tests/emu/dali_client.o $(TEST_LIBS)
	@mkdir -p $(dir $@)
	$(LINK)

tests: $(BUILD)/tests/psemu-run $(BUILD)/tests/dali-client
endif

# The emulated GPIO chip as an LD_PRELOAD fixture (tests/emu/vgpio*.c), for
# psensd with the gpio driver (tests/system/420).  Built without the
# sanitizers: it is loaded into whichever psensd the test runs.
ifeq ($(HAVE_GPIOD)$(shell $(PKG) --exists umockdev-1.0 && echo yes),yesyes)
VGPIO_SO := $(BUILD)/tests/libvgpio_fixture.so
$(VGPIO_SO): tests/emu/vgpio.c tests/emu/vgpio_fixture.c tests/emu/vgpio.h
	@mkdir -p $(dir $@)
	$(CC) -std=c11 $(WARN) -O2 -g -D_GNU_SOURCE -fPIC -shared \
	    $(patsubst -I%,-isystem %,$(shell $(PKG) --cflags umockdev-1.0)) -o $@ \
	    tests/emu/vgpio.c tests/emu/vgpio_fixture.c $(shell $(PKG) --libs umockdev-1.0)
tests: $(VGPIO_SO)
endif
