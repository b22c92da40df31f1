/* SPDX-License-Identifier: ISC */
/* The sky subdivisions of Tregenza (MF 1: 145 patches) and Reinhart (MF n:
 * each Tregenza patch cut n x n, the zenith cap kept whole), plus the
 * ground, numbered as Radiance's gendaymtx, reinhartb.cal and rfluxmtx
 * number them:
 *   patch 0         the ground (every direction at or below the horizon);
 *   patch 1         on the horizon row, centred due north (+Y);
 *   patches 2, ...  round the row with growing azimuth (from +Y towards +X,
 *                   east in Radiance's X east / Y north convention), then
 *                   row by row upwards;
 *   the last        the zenith cap.
 * Rows are alpha = 90 / (7 MF + 0.5) degrees high; row r (from 0 at the
 * horizon) holds 30, 30, 24, 24, 18, 12, 6 patches times MF for its
 * Tregenza band r / MF; the cap's half-angle is alpha / 2.  A patch's
 * direction is its centre: the middle altitude of its row and the middle
 * azimuth of its slice (the cap: the zenith).  Solid angles are exact. */
#ifndef PS_PATCHES_H
#define PS_PATCHES_H

#include "err.h"

#define PS_PATCHES_MF_MAX 64

struct ps_patches {
	int mf;              /* subdivision */
	int n;               /* patches, ground included: 144 mf^2 + 2 */
	int nrows;           /* 7 mf sky rows + the cap */
	double alpha;        /* row height, radians */
	int *row_count;      /* patches in each row (the cap: 1) */
	int *row_first;      /* index of each row's first patch */
	double *alt;         /* centre altitude, radians (ground: -pi/2) */
	double *azi;         /* centre azimuth from north towards east, radians */
	double *omega;       /* solid angle, sr (ground: 2 pi) */
	double *dir;         /* centre unit vector, 3 per patch (X east, Y north, Z up) */
	int *row;            /* row of each patch (ground: -1) */
};

/* Patches for subdivision mf (1 to PS_PATCHES_MF_MAX). */
int ps_patches_init(struct ps_patches *p, int mf, struct ps_err *e);
void ps_patches_free(struct ps_patches *p);
/* 144 mf^2 + 2. */
int ps_patches_count(int mf);
/* The subdivision with n patches (ground included), or -1 if none has. */
int ps_patches_mf_for_count(int n);
/* The patch a direction falls in (need not be normalised; 0 when z <= 0). */
int ps_patches_find(const struct ps_patches *p, const double d[3]);
/* Bounds of patch i (i >= 1): altitude from b[0] to b[1], azimuth from b[2]
 * to b[3] (b[2] may be negative: the north patches straddle 0). */
void ps_patches_bounds(const struct ps_patches *p, int i, double b[4]);

#endif
