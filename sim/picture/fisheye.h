/* SPDX-License-Identifier: ISC */
/* Fisheye projections as Radiance's viewray() defines them, in "plane"
 * coordinates (u, v) scaled so that the field's edge is at rho = 1:
 *   angular (-vta):       u = (fx - 0.5 + vs) vh/180,      theta = pi rho
 *   hemispherical (-vth): u = (fx - 0.5 + vs) 2 sin(vh/2), theta = asin rho
 * (v likewise with fy, vl and vv), fx = x / width measured from the picture's
 * left edge, fy from its bottom edge.  A direction's azimuth in the plane is
 * alpha = atan2(v, u); the sensor azimuth (0 = up, growing to the left) is
 * phi = alpha - 90 degrees.  rpict traces a -vta -vh 180 picture's corners
 * too (theta up to 127 degrees): they are real directions. */
#ifndef PS_FISHEYE_H
#define PS_FISHEYE_H

#include <math.h>

#include "view.h"

struct ps_fisheye {
	int type;            /* PS_VT_ANGULAR or PS_VT_HEMI */
	int width, height;
	double su, sv;       /* plane units per picture width and height */
	double u0, v0;       /* plane coordinates of the picture's bottom-left corner */
	double theta_field;  /* polar angle at the field's edge (pi or pi/2) */
};

void ps_fisheye_init(struct ps_fisheye *f, const struct ps_view *v, int width, int height);
/* Plane coordinate of pixel-corner column x (0..width) and line j (0..height, from the bottom). */
double ps_fisheye_u(const struct ps_fisheye *f, double x);
double ps_fisheye_v(const struct ps_fisheye *f, double j);
/* Polar angle of plane radius rho, clamped at the field's edge. */
static inline double ps_fisheye_theta(const struct ps_fisheye *f, double rho)
{
	/* inline: the exact weights take it at every quadrature node */
	if (rho >= 1.0)
		return f->theta_field;
	return f->type == PS_VT_HEMI ? asin(rho) : M_PI * rho;
}
/* Plane radius of polar angle theta (theta beyond the field gives 1). */
double ps_fisheye_rho(const struct ps_fisheye *f, double theta);
/* Solid angle per plane area at radius rho (0 outside the field). */
double ps_fisheye_jacobian(const struct ps_fisheye *f, double rho);
/* Direction of the centre of pixel (x, row) in standard orientation (row 0
 * at the top): polar angle and sensor azimuth in radians; -1 when the
 * centre is outside the field (Radiance traces no ray there). */
int ps_fisheye_pixel_dir(const struct ps_fisheye *f, int x, int row, double *theta, double *phi);
/* The smallest -vh (degrees) of this projection type whose square picture
 * holds every direction up to polar angle theta (radians). */
double ps_fisheye_vh_for(int type, double theta);

#endif
