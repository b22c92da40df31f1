/* SPDX-License-Identifier: ISC */
/* A work-plane grid as Radiance gives it: the points' daylight coefficients
 * as rfluxmtx -I+ (or rmtxop) writes a matrix, and their electric
 * irradiance as rtrace -I+ writes it.
 *
 * The matrix:
 *   #?RADIANCE
 *   <any header lines>
 *   NROWS=<points>
 *   NCOLS=<sky patches: 144 MF^2 + 2, ground first>
 *   NCOMP=3                      (1 is read as three equal components)
 *   BYTEORDER=LittleEndian|BigEndian   (binary; the machine's when absent)
 *   FORMAT=ascii|float|double
 *   <empty line>
 * then row by row (a point), column by column (a patch), the components:
 * ascii numbers separated by any white space (rfluxmtx writes a row a line,
 * tab-separated), or float / double binary without separators.  A value is
 * irradiance per unit patch radiance (W/m2 per W/sr/m2).
 *
 * The electric irradiance: one point a line, three numbers (R G B, W/m2),
 * as rtrace -h -I+ writes them; an optional Radiance header (rtrace without
 * -h) is skipped; blank lines and lines starting with # are ignored.  Lux is
 * 179 x (V(lambda)'s RGB coefficients . RGB).
 *
 * Everything refused names the file and its line (ascii) or byte (binary):
 * a missing or bad header field, a count no subdivision has, too few or
 * too many values, a number that is not one, NaN, infinity or a negative
 * coefficient. */
#ifndef PS_GRIDMTX_H
#define PS_GRIDMTX_H

#include <stddef.h>

#include "dcset.h"
#include "err.h"

struct ps_gridmtx {
	int npoints;         /* rows */
	int npatch;          /* columns, ground included */
	int mf;              /* the subdivision the columns make */
	double *c;           /* npoints x npatch x 3: c[3 (point npatch + patch) + k] */
};

/* Read a matrix file; on error m is left empty. */
int ps_gridmtx_read(struct ps_gridmtx *m, const char *path, struct ps_err *e);
/* The same from memory (name stands for the file in messages). */
int ps_gridmtx_parse(struct ps_gridmtx *m, const unsigned char *data, size_t len, const char *name,
                     struct ps_err *e);
void ps_gridmtx_free(struct ps_gridmtx *m);

/* Point i's row as a coefficient row (no copy: row->c points into m). */
void ps_gridmtx_row(const struct ps_gridmtx *m, int i, struct ps_dcset_row *row);

/* Read the electric irradiance of npoints points into lux[] (lux, V(lambda)).
 * A count other than npoints is refused naming the file and line. */
int ps_gridmtx_elec_read(const char *path, int npoints, double *lux, struct ps_err *e);
int ps_gridmtx_elec_parse(const char *text, size_t len, const char *name, int npoints, double *lux,
                          struct ps_err *e);

#endif
