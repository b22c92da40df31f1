/* SPDX-License-Identifier: ISC */
/* The CIE tables psensd ships (sim/data/cie, CC BY-SA 4.0): colour-matching
 * functions, V(lambda) and the illuminants, compiled in as data. */
#ifndef PS_CIE_H
#define PS_CIE_H

#include <stddef.h>

/* A table column on a uniform wavelength grid. */
struct ps_spectrum {
	const char *file;    /* table file name without .txt, e.g. "cie_illum_A_1nm" */
	int column;          /* 1-based value column in that file */
	double start, step;  /* nm */
	int n;
	const double *v;
};

/* NULL-terminated (file == NULL) list of every column of every table. */
extern const struct ps_spectrum ps_cie_tables[];

/* x-bar, y-bar, z-bar (k = 0, 1, 2) of the CIE 1931 2-degree observer. */
const struct ps_spectrum *ps_cie_cmf(int k);
/* V(lambda). */
const struct ps_spectrum *ps_cie_v(void);
/* An illuminant by name ("A", "D65", "FL2", ..., "HP1", "LED-B3"): the 1-nm
 * table where CIE publishes one, else the 5-nm one.  NULL if unknown. */
const struct ps_spectrum *ps_cie_illuminant(const char *name);
/* The illuminants the report covers, in order. */
extern const char *const ps_cie_illuminant_names[];
/* Value at a wavelength: linear between grid points, 0 outside the table. */
double ps_cie_spectrum_at(const struct ps_spectrum *s, double nm);

#endif
