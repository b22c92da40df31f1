/* SPDX-License-Identifier: ISC */
#include "lum.h"

#include "integrate.h"

void ps_lum_init(struct ps_lum *l, const struct ps_picture *pic)
{
	double m[3][3];
	if (pic->format == PS_PIC_XYZE) {
		/* luminance-based XYZ (Y in cd/m2): / 179 back to radiance,
		 * as ps_integrate_pic_matrix does for psens */
		ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, m);
		ps_integrate_mat3_invert((const double(*)[3])m, l->to_rgb);
		for (int i = 0; i < 3; i++)
			for (int k = 0; k < 3; k++)
				l->to_rgb[i][k] /= PS_LUM_EFFICACY;
	} else {
		if (pic->has_primaries)
			ps_integrate_own_rgb_to_xyz(pic->primaries, m);
		else
			ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, m);
		for (int i = 0; i < 3; i++)
			for (int k = 0; k < 3; k++)
				l->to_rgb[i][k] = i == k;
	}
	for (int k = 0; k < 3; k++)
		l->y[k] = m[1][k];
}

void ps_lum_rgb(const struct ps_lum *l, const struct ps_picture *pic, int x, int row, double rgb[3])
{
	double c[3];
	ps_picture_get(pic, x, row, c);
	for (int i = 0; i < 3; i++)
		rgb[i] = l->to_rgb[i][0] * c[0] + l->to_rgb[i][1] * c[1] + l->to_rgb[i][2] * c[2];
}

double ps_lum_y(const struct ps_lum *l, const double rgb[3])
{
	return l->y[0] * rgb[0] + l->y[1] * rgb[1] + l->y[2] * rgb[2];
}
