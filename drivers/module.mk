# SPDX-License-Identifier: ISC
# drivers/: which drivers this build compiles.  Included by the Makefile
# before its rules (it sets DRV_SRC, CFLAGS_ALL and LIBS_OPT).
#
# A driver with a library is optional: WITH_<NAME> = auto | yes | no.  auto
# drops it when pkg-config cannot find the library, yes makes that an error.
# A dropped driver stays in the registry (registry.c) as a stub that fails
# with "driver X not compiled in".  Adding one: a feature line and a gate
# below, and its #ifdef in registry.c (drivers/README.md).

WITH_MODBUS ?= auto
WITH_USB    ?= auto
WITH_GPIOD  ?= auto

# $(call feature,VAR,pkg,DEFINE) -> sets HAVE_<VAR> to yes/no
define feature
ifeq ($$(WITH_$(1)),no)
  HAVE_$(1) := no
else ifeq ($$(shell $$(PKG) --exists $(2) && echo yes),yes)
  HAVE_$(1) := yes
else ifeq ($$(WITH_$(1)),yes)
  $$(error WITH_$(1)=yes but pkg-config cannot find $(2))
else
  HAVE_$(1) := no
endif
ifeq ($$(HAVE_$(1)),yes)
  CFLAGS_ALL += -D$(3) $$(shell $$(PKG) --cflags $(2))
  LIBS_OPT   += $$(shell $$(PKG) --libs $(2))
endif
endef
LIBS_OPT :=
$(eval $(call feature,MODBUS,libmodbus,PS_WITH_MODBUS))
$(eval $(call feature,USB,libusb-1.0,PS_WITH_USB))
$(eval $(call feature,GPIOD,libgpiod,PS_WITH_GPIOD))

# every driver file; then the optional ones only when their library is there
DRV_SRC_ALL  := $(wildcard drivers/*.c)
DRV_MODBUS   := $(wildcard drivers/modbus*.c)
DRV_USB      := $(wildcard drivers/dali_usb*.c drivers/usb_*.c)
DRV_GPIOD    := $(wildcard drivers/gpio*.c)
DRV_SRC      := $(filter-out $(DRV_MODBUS) $(DRV_USB) $(DRV_GPIOD),$(DRV_SRC_ALL))
ifeq ($(HAVE_MODBUS),yes)
  DRV_SRC += $(DRV_MODBUS)
endif
ifeq ($(HAVE_USB),yes)
  DRV_SRC += $(DRV_USB)
endif
ifeq ($(HAVE_GPIOD),yes)
  DRV_SRC += $(DRV_GPIOD)
endif
