# SPDX-License-Identifier: ISC
# sim/: the CIE tables are compiled into libpsim from sim/data/cie/*.txt.
CIE_TXT := $(wildcard sim/data/cie/*.txt)
$(BUILD)/gen/cie_tables.c: $(CIE_TXT) sim/gen-cie.sh
	@mkdir -p $(dir $@)
	sh sim/gen-cie.sh sim/data/cie > $@.tmp && mv $@.tmp $@
$(BUILD)/obj/gen/cie_tables.o: $(BUILD)/gen/cie_tables.c sim/cie.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -Isim $(CFLAGS) -c -o $@ $<
$(LIBPSIM): $(BUILD)/obj/gen/cie_tables.o
