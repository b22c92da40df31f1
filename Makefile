# SPDX-License-Identifier: ISC
# psensd: one Makefile for the whole tree.  The layout is the architecture:
#   sim/      the simulation library (libpsim.a) and its tools in sim/cmd/
#   drivers/  device drivers behind one method table (libpsdrv.a); no simulation here
#   daemon/   psensd's core (libpsd.a) and its programs psensd, psensctl in
#             daemon/cmd/: joins sim/ and drivers/; one room per front end
#             (daemon/X/, libpsdX.a, a row of daemon/frontend.c): mqtt,
#             bacnet, web, prom; daemon/report/ (libpsdreport.a),
#             daemon/psvirt/ (psvirt and its Modbus server, libpsvirt.a),
#             daemon/place/ (psplace, the pose search, libpsdplace.a)
#   tests/    unit (cmocka), system (shell, real binaries), fuzz (libFuzzer), bench
# Every directory may add rules in its own module.mk (included below).
#
# Optional drivers: WITH_MODBUS / WITH_USB / WITH_GPIOD = auto | yes | no
# (and WITH_MQTT, the daemon's MQTT publisher, and WITH_WEB, its web
# console, the same way)
# (drivers/module.mk).  auto drops a driver whose library pkg-config cannot
# find; yes makes that an error.

CC      ?= gcc
BUILD   ?= build
PREFIX  ?= /usr/local
DESTDIR ?=
SAN     ?=
PKG     ?= pkg-config

WARN    = -Wall -Wextra -Werror -Wshadow -Wformat=2 -Wstrict-prototypes \
          -Wmissing-prototypes -Wpointer-arith -Wvla
OPT     ?= -O2 -g
CPPFLAGS_BASE = -D_GNU_SOURCE
CFLAGS_ALL    = -std=c11 $(WARN) $(OPT) $(CPPFLAGS_BASE)
LDLIBS_BASE   = -lm -pthread

ifeq ($(SAN),1)
  CFLAGS_ALL += -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
  LDFLAGS    += -fsanitize=address,undefined
endif

# ---- required libraries ---------------------------------------------------
# cairo draws the pictures' marks and legends (its text through fontconfig),
# libpng writes them (sim/draw/canvas.c)
REQ_PKGS = sqlite3 inih libsystemd nettle json-c cairo libpng fontconfig
CFLAGS_ALL += $(shell $(PKG) --cflags $(REQ_PKGS) 2>/dev/null)
LIBS_REQ   := $(shell $(PKG) --libs $(REQ_PKGS) 2>/dev/null)

# ---- sources --------------------------------------------------------------
SIM_DIRS     := sim sim/picture sim/sky sim/weights sim/draw
SIM_SRC      := $(foreach d,$(SIM_DIRS),$(wildcard $(d)/*.c))
SIM_CMDS     := $(patsubst sim/cmd/%.c,%,$(wildcard sim/cmd/*.c))
# drivers/module.mk: which drivers this build compiles (DRV_SRC), their
# libraries, and HAVE_MODBUS / HAVE_USB / HAVE_GPIOD.  Included here, before
# the rules that use DRV_SRC.
include drivers/module.mk
DAEMON_SRC   := $(wildcard daemon/*.c)
# MQTT (daemon/mqtt/, psensd-mqtt(7)) and the web console (daemon/web/,
# doc/console.md): WITH_MQTT, WITH_WEB = auto | yes | no, like the drivers.
# Without its library a front end's X_off.c stands in (see frontend below).
WITH_MQTT ?= auto
$(eval $(call feature,MQTT,libmosquitto,PS_WITH_MQTT))
WITH_WEB ?= auto
$(eval $(call feature,WEB,libmicrohttpd,PS_WITH_WEB))
REPORT_SRC   := $(wildcard daemon/report/*.c)
# The record's QR codes to the web console ([web] url): WITH_QRENCODE =
# auto | yes | no; without libqrencode the record has none.
WITH_QRENCODE ?= auto
$(eval $(call feature,QRENCODE,libqrencode,PS_WITH_QRENCODE))
# psvirt's room: its main (psvirt.c) and the library of its Modbus server
PSVIRT_SRC   := $(filter-out daemon/psvirt/psvirt.c,$(wildcard daemon/psvirt/*.c))
# psplace's room: its main (psplace.c) and the library of the pose search
PLACE_SRC    := $(filter-out daemon/place/psplace.c,$(wildcard daemon/place/*.c))
CORE_CMDS    := $(patsubst daemon/cmd/%.c,%,$(wildcard daemon/cmd/*.c))
DAEMON_CMDS  := $(CORE_CMDS) psplace
# psvirt serves the virtual room over Modbus: it needs libmodbus.
ifeq ($(HAVE_MODBUS),yes)
  DAEMON_CMDS += psvirt
endif

obj = $(patsubst %.c,$(BUILD)/obj/%.o,$(1))

# A front end of psensd (daemon/frontend.h): $(call frontend,X[,FEATURE])
# builds its room daemon/X/ into libpsdX.a, puts the room's public header
# X.h on the core's include path and links it into every program of the
# core.  With a FEATURE whose library this build lacks (HAVE_FEATURE not
# yes), X_off.c stands in for X.c: the section is still judged, and a
# configured one is refused at start.  Its row goes in daemon/frontend.c.
define frontend
FRONT_SRC_$(1) := $$(filter-out daemon/$(1)/$(1)$$(if $$(filter yes,$$(or $$(HAVE_$(2)),yes)),_off).c,\
                  $$(wildcard daemon/$(1)/*.c))
LIBPSD_FRONTS += $$(BUILD)/lib/libpsd$(1).a
INC_FRONTS += -iquote daemon/$(1)
$$(BUILD)/lib/libpsd$(1).a: $$(call obj,$$(FRONT_SRC_$(1)))
	@mkdir -p $$(dir $$@)
	rm -f $$@ && ar rcs $$@ $$^
endef
LIBPSD_FRONTS :=
INC_FRONTS :=
$(eval $(call frontend,mqtt,MQTT))
$(eval $(call frontend,bacnet))
$(eval $(call frontend,web,WEB))
$(eval $(call frontend,prom))

LIBPSIM   = $(BUILD)/lib/libpsim.a
LIBPSDRV  = $(BUILD)/lib/libpsdrv.a
LIBPSD    = $(BUILD)/lib/libpsd.a
LIBPSDREPORT = $(BUILD)/lib/libpsdreport.a
LIBPSVIRT    = $(BUILD)/lib/libpsvirt.a
LIBPSDPLACE  = $(BUILD)/lib/libpsdplace.a
# the daemon's core with its front ends: config.c judges their sections
# (their *conf.c) and the loop runs them through the front-end table
# (daemon/frontend.c), which drive the engine; the web console serves the
# record (report room)
LIBPSD_CORE  = $(LIBPSD_FRONTS) $(LIBPSDREPORT) $(LIBPSD) $(LIBPSDRV) $(LIBPSIM)
PROGRAMS  = $(addprefix $(BUILD)/bin/,$(SIM_CMDS) $(DAEMON_CMDS))
LIBS      = $(LIBS_REQ) $(LIBS_OPT) $(LDLIBS_BASE)

.PHONY: all check bench fuzz install uninstall clean deps deps-peers run sim drivers daemon config-status tests fuzz-bins
all: $(PROGRAMS)

sim: $(addprefix $(BUILD)/bin/,$(SIM_CMDS))
drivers: $(LIBPSDRV)
daemon: $(addprefix $(BUILD)/bin/,$(DAEMON_CMDS))

config-status:
	@echo "modbus=$(HAVE_MODBUS) usb=$(HAVE_USB) gpiod=$(HAVE_GPIOD) mqtt=$(HAVE_MQTT) web=$(HAVE_WEB) qrencode=$(HAVE_QRENCODE) cc=$(CC) build=$(BUILD) san=$(SAN)"

# The include path enforces the layering: sim/ sees only sim/, drivers/ only
# drivers/ (SIM_INC: sim/ and each of its folders); the daemon's core sees sim/, drivers/, itself and each front
# end's folder for its public header (daemon/X/X.h: tests/system/005 keeps
# the rest of the room out of the core); a room sees the core and itself; the programs in
# daemon/cmd/ and tests/ see everything.  daemon/ and its rooms are
# -iquote: daemon/time.h and json.h are found by #include "..." only, never
# in place of the system's <time.h> or json-c's json.h.
SIM_INC = $(addprefix -I,$(SIM_DIRS))
INC_CORE = $(SIM_INC) -Idrivers -iquote daemon $(INC_FRONTS)
INC = $(INC_CORE) -iquote daemon/report -iquote daemon/psvirt
$(BUILD)/obj/sim/%.o: INC = $(SIM_INC)
$(BUILD)/obj/drivers/%.o: INC = -Idrivers
$(BUILD)/obj/daemon/%.o: INC = $(INC_CORE)
$(BUILD)/obj/daemon/report/%.o: INC = $(INC_CORE) -iquote daemon/report
$(BUILD)/obj/daemon/psvirt/%.o: INC = $(INC_CORE) -iquote daemon/psvirt
$(BUILD)/obj/daemon/place/%.o: INC = $(INC_CORE) -iquote daemon/place
$(BUILD)/obj/daemon/web/%.o: INC = $(INC_CORE) -iquote daemon/report -iquote $(BUILD)/gen/web
# the console's pages, built in (daemon/web/genassets.sh: od and sed)
WEB_ASSETS := $(sort $(wildcard daemon/web/assets/*))
$(BUILD)/gen/web/webassets.inc: daemon/web/genassets.sh $(WEB_ASSETS)
	@mkdir -p $(dir $@)
	sh daemon/web/genassets.sh $(WEB_ASSETS) > $@.tmp && mv $@.tmp $@
$(BUILD)/obj/daemon/web/webasset.o: $(BUILD)/gen/web/webassets.inc
$(BUILD)/obj/daemon/cmd/%.o: INC = $(INC_CORE) -iquote daemon/report -iquote daemon/psvirt
$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(INC) $(CFLAGS) -MMD -MP -c -o $@ $<

$(LIBPSIM): $(call obj,$(SIM_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBPSDRV): $(call obj,$(DRV_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBPSD): $(call obj,$(DAEMON_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBPSDREPORT): $(call obj,$(REPORT_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBPSVIRT): $(call obj,$(PSVIRT_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBPSDPLACE): $(call obj,$(PLACE_SRC))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

# Link $@ from the objects and archives among its prerequisites.  The
# archives are one group: the core and the MQTT room use each other.
LINK = $(CC) $(CFLAGS_ALL) $(LDFLAGS) -o $@ $(filter-out %.a,$^) \
       -Wl,--start-group $(filter %.a,$^) -Wl,--end-group $(LIBS)

# sim tools link only the simulation library: sim/ knows nothing of devices.
$(addprefix $(BUILD)/bin/,$(SIM_CMDS)): $(BUILD)/bin/%: $(BUILD)/obj/sim/cmd/%.o $(LIBPSIM)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) $(LDFLAGS) -o $@ $^ $(LIBS)

# psensd: the core (with MQTT); psensctl: the core and the record; psvirt:
# its room and the core.
$(addprefix $(BUILD)/bin/,$(CORE_CMDS)): $(BUILD)/bin/%: $(BUILD)/obj/daemon/cmd/%.o $(LIBPSD_CORE)
	@mkdir -p $(dir $@)
	$(LINK)
$(BUILD)/bin/psensctl: $(LIBPSDREPORT)
$(BUILD)/bin/psvirt: $(BUILD)/obj/daemon/psvirt/psvirt.o $(LIBPSVIRT) $(LIBPSD_CORE)
	@mkdir -p $(dir $@)
	$(LINK)
# psplace: its room (the pose search) and the core (the laws and devices).
$(BUILD)/bin/psplace: $(BUILD)/obj/daemon/place/psplace.o $(LIBPSDPLACE) $(LIBPSD_CORE)
	@mkdir -p $(dir $@)
	$(LINK)

-include $(filter-out drivers/module.mk,$(wildcard */module.mk))
-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)

# ---- Debian packages the build and the tests need -------------------------
# Installed by `make deps` (and so by the README's two commands) when run as root.
# (python3-serial-asyncio is only a Recommends of python3-pymodbus, whose
# client and server modules import it: deps.sh installs no recommends.)
DEB_BUILD = gcc clang make pkg-config libsqlite3-dev sqlite3 libinih-dev libsystemd-dev nettle-dev \
            libcmocka-dev libjson-c-dev libmodbus-dev libusb-1.0-0-dev libgpiod-dev \
            libcairo2-dev libpng-dev libfontconfig-dev fonts-dejavu-core libmosquitto-dev \
            libmicrohttpd-dev libqrencode-dev
DEB_TEST  = umockdev libumockdev-dev gpiod python3 python3-pymodbus python3-serial-asyncio mbpoll socat valgrind libxml2-utils \
            libclang-rt-14-dev systemd pngcheck poppler-utils librsvg2-bin mosquitto mosquitto-clients openssl \
            nodejs tzdata chromium zbar-tools prometheus tshark
deps:
	@sh tests/deps.sh $(DEB_BUILD) $(DEB_TEST)
# the test peers (npm): make check's, not make run's, which has no use for them
deps-peers: deps
	@# npm: Debian's package, unless the nodejs installed carries its own
	@command -v npm >/dev/null 2>&1 || sh tests/deps.sh npm
	@# the BACnet peer and the browser's driver (tests/peers/package.json,
	@# pinned by its lock file; puppeteer-core downloads no browser)
	@if [ ! -d tests/peers/node_modules ] || [ tests/peers/package-lock.json -nt tests/peers/node_modules ]; then \
	    (cd tests/peers && npm ci --no-audit --no-fund --loglevel=error) || \
	    echo "deps: npm ci in tests/peers failed: the BACnet and web console tests will skip" >&2; fi

clean:
	rm -rf $(BUILD) $(BUILD)-fuzz

# ---- install ---------------------------------------------------------------
SYSCONFDIR ?= /etc
UNITDIR    ?= /lib/systemd/system
SYSUSERSDIR ?= /usr/lib/sysusers.d
UDEVRULESDIR ?= /usr/lib/udev/rules.d
DATADIR    ?= $(PREFIX)/share/psensd
MANDIR     ?= $(PREFIX)/share/man
STATEDIR   ?= /var/lib/psensd
MAN_PAGES  := $(wildcard sim/cmd/*.[1-8] daemon/*/*.[1-8] drivers/*.[1-8] config/*.[1-8])
install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/sbin
	install -m 755 $(addprefix $(BUILD)/bin/,$(SIM_CMDS) $(filter-out psensd,$(DAEMON_CMDS))) $(DESTDIR)$(PREFIX)/bin/
	if [ -f $(BUILD)/bin/psensd ]; then install -m 755 $(BUILD)/bin/psensd $(DESTDIR)$(PREFIX)/sbin/; fi
	for m in $(MAN_PAGES); do s=$${m##*.}; install -d $(DESTDIR)$(MANDIR)/man$$s; \
	    install -m 644 $$m $(DESTDIR)$(MANDIR)/man$$s/; done
	install -d $(DESTDIR)$(SYSCONFDIR)/psensd
	# the example configuration, pointed at the installed example scene
	for f in config/*.conf; do [ -f "$$f" ] || continue; \
	    [ -f $(DESTDIR)$(SYSCONFDIR)/psensd/$${f##*/} ] || \
	    $(INSTALLED_CONF) $$f > $(DESTDIR)$(SYSCONFDIR)/psensd/$${f##*/}; done
	if [ -f systemd/psensd.service ]; then install -d $(DESTDIR)$(UNITDIR); \
	    sed 's|@SBINDIR@|$(PREFIX)/sbin|g; s|@SYSCONFDIR@|$(SYSCONFDIR)|g' systemd/psensd.service \
	    > $(DESTDIR)$(UNITDIR)/psensd.service; chmod 644 $(DESTDIR)$(UNITDIR)/psensd.service; fi
	install -d $(DESTDIR)$(SYSUSERSDIR) $(DESTDIR)$(UDEVRULESDIR)
	install -m 644 systemd/psensd.sysusers $(DESTDIR)$(SYSUSERSDIR)/psensd.conf
	install -m 644 systemd/60-psensd.rules $(DESTDIR)$(UDEVRULESDIR)/60-psensd.rules
	install -d $(DESTDIR)$(DATADIR) $(DESTDIR)$(STATEDIR)
	cp -R config/example $(DESTDIR)$(DATADIR)/
	if [ -d sim/data ]; then cp -R sim/data/. $(DESTDIR)$(DATADIR)/; fi

# make uninstall: removes what make install put there (same PREFIX, DESTDIR
# and directories): the programs, the man pages, the unit, sysusers and udev
# files, the example and data under DATADIR, the configuration when it is
# still the one install wrote (an edited one is kept, and said so), and the
# psensd directories it made when they are left empty.
INSTALLED_CONF = sed 's|^scene = example/|scene = $(DATADIR)/example/|; s|^results = .*|results = $(STATEDIR)/ofb.results|; s|^database = .*|database = $(STATEDIR)/psensd.db|'
uninstall:
	rm -f $(addprefix $(DESTDIR)$(PREFIX)/bin/,$(SIM_CMDS) $(filter-out psensd,$(DAEMON_CMDS))) $(DESTDIR)$(PREFIX)/sbin/psensd
	for m in $(MAN_PAGES); do s=$${m##*.}; rm -f $(DESTDIR)$(MANDIR)/man$$s/$${m##*/}; done
	for f in config/*.conf; do [ -f "$$f" ] || continue; i=$(DESTDIR)$(SYSCONFDIR)/psensd/$${f##*/}; \
	    [ -f "$$i" ] || continue; \
	    if $(INSTALLED_CONF) $$f | cmp -s - "$$i"; then rm -f "$$i"; \
	    else echo "uninstall: $$i was edited: kept"; fi; done
	-rmdir $(DESTDIR)$(SYSCONFDIR)/psensd 2>/dev/null
	rm -f $(DESTDIR)$(UNITDIR)/psensd.service $(DESTDIR)$(SYSUSERSDIR)/psensd.conf \
	    $(DESTDIR)$(UDEVRULESDIR)/60-psensd.rules
	(cd config && find example -type f) | while read -r f; do rm -f "$(DESTDIR)$(DATADIR)/$$f"; done
	if [ -d sim/data ]; then (cd sim/data && find . -type f) | while read -r f; do \
	    rm -f "$(DESTDIR)$(DATADIR)/$$f"; done; fi
	-[ -d $(DESTDIR)$(DATADIR) ] && find $(DESTDIR)$(DATADIR) -depth -type d -empty -delete
	-rmdir $(DESTDIR)$(STATEDIR) 2>/dev/null

# ---- the README's main command ----------------------------------------------
# psensd on the loopback room with the example scene, for a simulated day:
# precomputes the scene's ratios (psscene) when they are stale, then prints
# the day's summary.  Quiet: the build's commands go to $(BUILD)/build.log
# (shown when the build fails); V=1 shows them and the commands run.
V ?= 0
# the quiet build's stages (target:what, _ for a space): a line on standard
# error before each that has work, so a first build of a minute or two is
# not silent
RUN_STAGES = sim:the_simulation_library_and_its_tools,_sim/ drivers:the_device_drivers,_drivers/ \
             daemon:psensd_and_its_front_ends,_daemon/ all:the_rest
run: deps
	@if [ "$(V)" = 1 ]; then \
	    echo "$(MAKE) all"; $(MAKE) --no-print-directory all || exit 1; \
	    echo "$(BUILD)/bin/psensd -f config/psensd.conf -s"; \
	else \
	    mkdir -p $(BUILD); : > $(BUILD)/build.log; \
	    for s in $(RUN_STAGES); do \
	        $(MAKE) -q --no-print-directory $${s%%:*} > /dev/null 2>&1 || \
	            echo "building $$(echo "$${s#*:}" | tr _ ' ') ..." >&2; \
	        $(MAKE) --no-print-directory $${s%%:*} >> $(BUILD)/build.log 2>&1 || \
	        { cat $(BUILD)/build.log; echo "make run: the build failed ($(BUILD)/build.log)" >&2; exit 1; }; \
	    done; \
	fi
	@# config/psensd.conf keeps the example's results and log in build/,
	@# whatever BUILD this make uses
	@mkdir -p build
	@$(BUILD)/bin/psensd -f config/psensd.conf -s

# The golden day (tests/data/golden-day.csv): run the example day again, say
# how and why it differs from the file, and rewrite it (tests/golden/).
golden: all
	BUILD=$(BUILD) BIN=$(BUILD)/bin sh tests/golden/rebuild.sh
.PHONY: golden
