# SPDX-License-Identifier: ISC
# sim/: the CIE tables are compiled into libpsim from sim/data/cie/*.txt.
CIE_TXT := $(wildcard sim/data/cie/*.txt)
$(BUILD)/gen/cie_tables.c: $(CIE_TXT) sim/gen-cie.sh
	@mkdir -p $(dir $@)
	sh sim/gen-cie.sh sim/data/cie > $@.tmp && mv $@.tmp $@
$(BUILD)/obj/gen/cie_tables.o: $(BUILD)/gen/cie_tables.c sim/weights/cie.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(SIM_INC) $(CFLAGS) -c -o $@ $<
$(LIBPSIM): $(BUILD)/obj/gen/cie_tables.o

# The integration's run kernel has an AVX2 build (sim/weights/rowsum_avx2.c), run
# only where the processor has AVX2 (sim/weights/rowsum.c asks); on other machines
# the file builds as an empty stand-in.
ifneq ($(filter x86_64-% i686-% i386-% amd64-%,$(shell $(CC) -dumpmachine)),)
$(BUILD)/obj/sim/weights/rowsum_avx2.o: CFLAGS_ALL += -mavx2
endif
