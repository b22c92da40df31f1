/* SPDX-License-Identifier: ISC */
#include "fisheye.h"

#include <math.h>

void ps_fisheye_init(struct ps_fisheye *f, const struct ps_view *v, int width, int height)
{
	f->type = v->type;
	f->width = width;
	f->height = height;
	if (v->type == PS_VT_HEMI) {
		f->su = 2.0 * sin(v->vh * (M_PI / 360.0));
		f->sv = 2.0 * sin(v->vv * (M_PI / 360.0));
		f->theta_field = M_PI / 2;
	} else {
		f->su = v->vh / 180.0;
		f->sv = v->vv / 180.0;
		f->theta_field = M_PI;
	}
	f->u0 = (v->vs - 0.5) * f->su;
	f->v0 = (v->vl - 0.5) * f->sv;
}

double ps_fisheye_u(const struct ps_fisheye *f, double x)
{
	return f->u0 + (x / f->width) * f->su;
}

double ps_fisheye_v(const struct ps_fisheye *f, double j)
{
	return f->v0 + (j / f->height) * f->sv;
}

double ps_fisheye_rho(const struct ps_fisheye *f, double theta)
{
	if (theta >= f->theta_field)
		return 1.0;
	return f->type == PS_VT_HEMI ? sin(theta) : theta / M_PI;
}

double ps_fisheye_jacobian(const struct ps_fisheye *f, double rho)
{
	if (rho > 1.0)
		return 0.0;
	if (f->type == PS_VT_HEMI)
		return rho < 1.0 ? 1.0 / sqrt(1.0 - rho * rho) : INFINITY;
	if (rho < 1e-8)
		return M_PI * M_PI;
	return M_PI * sin(M_PI * rho) / rho;
}

int ps_fisheye_pixel_dir(const struct ps_fisheye *f, int x, int row, double *theta, double *phi)
{
	double u = ps_fisheye_u(f, x + 0.5);
	double v = ps_fisheye_v(f, f->height - row - 0.5);
	double rho = hypot(u, v);
	if (rho > 1.0)
		return -1;
	*theta = ps_fisheye_theta(f, rho);
	*phi = atan2(v, u) - M_PI / 2;
	return 0;
}

double ps_fisheye_vh_for(int type, double theta)
{
	/* the square's edge midpoints are the nearest field points: rho = su / 2 */
	if (type == PS_VT_HEMI)
		return theta >= M_PI / 2 ? 180.0 : 360.0 / M_PI * asin(sin(theta));
	return fmin(360.0, 360.0 * theta / M_PI);
}
