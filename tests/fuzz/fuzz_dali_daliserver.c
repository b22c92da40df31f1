/* SPDX-License-Identifier: ISC */
/* Fuzz the daliserver DALI codec (drivers/dali_daliserver.c): decoder and
 * encoder, with the checks every stream codec shares (dali_codec_fuzz.h). */
#include "dali_daliserver.h"

#define FUZZ_DALI_CODEC ps_dali_daliserver
#include "dali_codec_fuzz.h"
