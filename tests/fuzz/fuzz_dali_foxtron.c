/* SPDX-License-Identifier: ISC */
/* Fuzz the foxtron DALI codec (drivers/dali_foxtron.c): decoder and encoder, with
 * the checks every serial codec shares (dali_codec_fuzz.h). */
#include "dali_foxtron.h"

#define FUZZ_DALI_CODEC ps_dali_foxtron
#include "dali_codec_fuzz.h"
