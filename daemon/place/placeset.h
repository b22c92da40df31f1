/* SPDX-License-Identifier: ISC */
/* The candidate poses: the list (an id and a Radiance view a line), each
 * pose's coefficient pictures and electric picture read and projected once
 * per channel (rescan.h) with every sensor read at every rotation, and the
 * exact route (ps_dcset_row at one rotation) for the re-check.  Errors name
 * the candidate (and its file). */
#ifndef PSD_PLACESET_H
#define PSD_PLACESET_H

#include <stddef.h>

#include "picture.h"
#include "place.h"

/* Read s->o->cands into s->poses.  -1 with err. */
int psd_placeset_read(struct search *s, char *err, size_t errlen);
/* Add the poses of s->o->ceiling ("X0,X1,NX,Y0,Y1,NY,Z": NX x NY points at
 * height Z) with each aim of s->o->aims ("down", or "TILT@AZIMUTH": tilted
 * TILT degrees from straight down toward the plan azimuth AZIMUTH, degrees
 * from +y toward +x; default "down").  Ids g00, g01 ... (x fastest), with
 * -A for the aim A (from 1) when there are several.  -1 with err. */
int psd_placeset_grid(struct search *s, char *err, size_t errlen);
/* Read pose p's electric picture (DIR/id/elec.hdr or elec_128.hdr, or the
 * rendered one).  -1 with err naming the candidate. */
int psd_placeset_elec_read(const struct search *s, const struct pose *p, struct ps_picture *pic, char *err,
                           size_t errlen);
/* Read and project pose p: p->row (rotations x sensors x patches x 3) and
 * p->elec.  -1 with err naming the candidate. */
int psd_placeset_project(struct search *s, struct pose *p, char *err, size_t errlen);
/* The exact route for pose p, sensor k at rot degrees: row (patches x 3)
 * and the electric response. */
int psd_placeset_exact(const struct search *s, const struct pose *p, int k, double rot, double *row, double *elec,
                       char *err, size_t errlen);

#endif
