/* SPDX-License-Identifier: ISC */
/* What the search writes: the ranked table, the JSON, the winner's year
 * (EnergyPlus Schedule:File, a plain CSV), its results and zone section,
 * and the plan of the poses as a PNG. */
#ifndef PSD_PLACEOUT_H
#define PSD_PLACEOUT_H

#include <stddef.h>
#include <stdio.h>

#include "place.h"

void psd_placeout_table(const struct search *s, size_t rows);
int psd_placeout_json(const struct search *s, FILE *fp, double seconds);
/* The winner's exports that s->o asks for.  -1 with err. */
int psd_placeout_exports(const struct search *s, const struct combo *k0, char *err, size_t errlen);
/* The best combination k's sensor, at its rotation, over its pose's
 * fisheye (the electric picture): a PNG as mksens --overlay draws it. */
int psd_placeout_fisheye(const struct search *s, const struct combo *k, const char *path, char *err, size_t errlen);
int psd_placeout_plan(const struct search *s, const char *path, char *err, size_t errlen);

#endif
