/* SPDX-License-Identifier: ISC */
/* Which part of the scene each pixel of a fisheye view sees: the regions a
 * sensor's signal is split into.
 *
 * From geometry (ps_radgeom): each pixel is cut into sub x sub samples at the
 * centres of a regular grid in the picture plane; each sample's ray, from
 * the view point in the direction Radiance's viewray() gives it, is labelled
 * with the group of the first surface it meets ("(nothing)" when it meets
 * none), and weighted by the projection's solid angle per plane area there.
 * A pixel's parts are its labels with the fraction of its solid angle each
 * holds; its major label is the largest.
 *
 * Groups of surface identifiers (genbox's face suffix, a final '.' and
 * digits, is taken off first):
 *   auto      the identifier's first word (up to its first '_') when another
 *             surface shares that word, else the whole identifier:
 *             desk_top, desk_leg_l -> desk; back_wall (alone) -> back_wall
 *   name      the identifier
 *   material  the surface's material (modifier)
 *
 * Without geometry: angular sectors, the polar-angle bands 0-30, 30-60,
 * 60-90 and beyond 90 degrees from the view direction, each in the four
 * quadrants around the picture's up (azimuth 0), left (90), down (180) and
 * right (270). */
#ifndef PS_REGIONS_H
#define PS_REGIONS_H

#include <stddef.h>

#include "err.h"
#include "radgeom.h"
#include "view.h"

enum ps_group { PS_GROUP_AUTO = 0, PS_GROUP_NAME, PS_GROUP_MATERIAL };

struct ps_region_part {
	int label;
	double frac;          /* of the pixel's solid angle */
};

struct ps_regions {
	int width, height, sub;
	int sectors;          /* 1: angular sectors, not geometry */
	int nlabels;
	char **label;         /* region names */
	int *major;           /* per pixel (row-major, row 0 at the top): largest label, -1 outside the field */
	size_t *off;          /* pixel p's parts are part[off[p]] .. part[off[p + 1] - 1] */
	struct ps_region_part *part;
	size_t npart;
};

/* "auto", "name" or "material"; -1 otherwise. */
int ps_regions_group_parse(const char *name);
/* The group of each surface (names[i] for g->poly[i], pointers into *labels):
 * *labels holds the distinct groups in order of first appearance. */
int ps_regions_groups(const struct ps_radgeom *g, int group, char ***labels, int *nlabels,
                      int **of_poly, struct ps_err *e);

/* Label a fisheye view (-vta or -vth) of width x height pixels. */
int ps_regions_geometry(struct ps_regions *r, const struct ps_radgeom *g, int group,
                        const struct ps_view *v, int width, int height, int sub, struct ps_err *e);
int ps_regions_sectors(struct ps_regions *r, const struct ps_view *v, int width, int height,
                       int sub, struct ps_err *e);
void ps_regions_free(struct ps_regions *r);

#endif
