# SPDX-License-Identifier: ISC
# daemon/: test tools that join the drivers and the daemon's control law.
# mbdrive (tests/system/peers/mbdrive.c) runs the Modbus driver from the
# command line for the 3xx system tests and the Modbus benchmark.
ifeq ($(HAVE_MODBUS),yes)
MBDRIVE = $(BUILD)/tests/mbdrive
$(MBDRIVE): $(BUILD)/obj/tests/system/peers/mbdrive.o $(LIBPSD_CORE)
	@mkdir -p $(dir $@)
	$(LINK)
TEST_EXTRA += $(MBDRIVE)
bench: $(MBDRIVE)
endif
