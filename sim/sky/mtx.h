/* SPDX-License-Identifier: ISC */
/* Radiance's matrix files as gendaymtx writes them (read by dctimestep,
 * rmtxop):
 *   #?RADIANCE
 *   <the command line>
 *   LATLONG= <latitude> <longitude east>      (when the caller gives a site)
 *   NROWS=<rows>
 *   NCOLS=<columns>
 *   NAVERAGED=<steps>                         (an average, when given)
 *   NCOMP=3
 *   BYTEORDER=LittleEndian|BigEndian          (binary formats)
 *   FORMAT=ascii|float|double
 *   <empty line>
 * then, row by row (a sky patch), column by column (a time step), the three
 * components: ascii "%.3g %.3g %.3g" (or more digits) a line with an empty line after each
 * row when there is more than one column; float or double in the machine's
 * byte order, no separators. */
#ifndef PS_MTX_H
#define PS_MTX_H

#include <stdio.h>

#include "err.h"

enum ps_mtx_format { PS_MTX_ASCII = 'a', PS_MTX_FLOAT = 'f', PS_MTX_DOUBLE = 'd' };

struct ps_mtx_header {
	const char *command;     /* the command line (NULL: none) */
	int has_latlong;
	double lat, lon;         /* degrees north, degrees east */
	int nrows, ncols;
	int naveraged;           /* > 0: write NAVERAGED= */
	int format;              /* enum ps_mtx_format */
	int digits;              /* ascii: significant digits (0: 3, as gendaymtx) */
};

/* Write the header (unless header is 0) and the data: element (row r,
 * column c, component k) at data[3 (c nrows + r) + k], floats or doubles
 * as data_double says.  path names the output in messages. */
int ps_mtx_write(FILE *fp, const char *path, const struct ps_mtx_header *h, int header,
                 const void *data, int data_double, struct ps_err *e);

#endif
