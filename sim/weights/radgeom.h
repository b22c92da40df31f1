/* SPDX-License-Identifier: ISC */
/* The geometry of a Radiance scene description, enough to say which surface
 * a ray from a viewpoint meets first (the regions psshare names).
 *
 * Read: `polygon` primitives (0 string, 0 integer and 3n >= 9 real
 * arguments), and the commands `!genbox MAT NAME X Y Z [-i]` piped to any
 * number of `xform` stages with -t X Y Z, -rx/-ry/-rz DEG, -s S,
 * -mx/-my/-mz and -m MAT, applied in the order given (genbox's faces are
 * named NAME.1540, NAME.4620, NAME.2310, NAME.3267, NAME.5137, NAME.6457
 * as genbox names them).  Every other primitive type is taken for a material,
 * pattern or other modifier and skipped, and `source` (at infinity) too;
 * the other surface types (sphere, bubble, cone, cup, cylinder, tube, ring,
 * instance, mesh), any other command and any other xform option are refused
 * with file:line. */
#ifndef PS_RADGEOM_H
#define PS_RADGEOM_H

#include <stddef.h>

#include "err.h"

struct ps_radpoly {
	char *name;           /* identifier */
	char *material;       /* modifier */
	int file, line;       /* index into files[], line of the primitive or command */
	int nv;
	double *v;            /* 3 nv coordinates */
	double n[3], d;       /* plane: n . x = d, |n| = 1 */
	double lo[3], hi[3];  /* bounding box */
	int a0, a1;           /* the two axes the polygon is projected on */
};

struct ps_radgeom {
	struct ps_radpoly *poly;
	size_t npoly, cap;
	char **files;
	int nfiles;
	size_t skipped;       /* modifiers and sources passed over */
	size_t degenerate;    /* polygons without area (dropped, as Radiance does) */
};

void ps_radgeom_init(struct ps_radgeom *g);
/* Add the surfaces of a scene description held in memory (name for messages).
 * On error returns -1 with file:line in e->msg; surfaces read before the
 * error stay. */
int ps_radgeom_parse(struct ps_radgeom *g, const char *text, size_t len, const char *name,
                     struct ps_err *e);
/* The same from a file. */
int ps_radgeom_read(struct ps_radgeom *g, const char *path, struct ps_err *e);
void ps_radgeom_free(struct ps_radgeom *g);

/* The first surface a ray meets (index into poly[]), -1 when none; *t the
 * distance along dir (which need not be unit). */
long ps_radgeom_trace(const struct ps_radgeom *g, const double org[3], const double dir[3],
                      double *t);

#endif
