/* SPDX-License-Identifier: ISC */
/* Fuzz the atx DALI codec (drivers/dali_atx.c): decoder and encoder, with
 * the checks every serial codec shares (dali_codec_fuzz.h). */
#include "dali_atx.h"

#define FUZZ_DALI_CODEC ps_dali_atx
#include "dali_codec_fuzz.h"
