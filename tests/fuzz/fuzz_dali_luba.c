/* SPDX-License-Identifier: ISC */
/* Fuzz the luba DALI codec (drivers/dali_luba.c): decoder and encoder, with
 * the checks every serial codec shares (dali_codec_fuzz.h). */
#include "dali_luba.h"

#define FUZZ_DALI_CODEC ps_dali_luba
#include "dali_codec_fuzz.h"
