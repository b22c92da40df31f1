/* SPDX-License-Identifier: ISC */
#include "dcpic.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fisheye.h"
#include "integrate.h"

static void unit(double v[3])
{
	double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	for (int k = 0; k < 3; k++)
		v[k] /= n;
}

void ps_dcpic_frame(const struct ps_view *v, double f[3][3])
{
	double *up = f[0], *left = f[1], *dir = f[2], k;
	memcpy(dir, v->vd, 3 * sizeof *dir);
	unit(dir);
	k = v->vu[0] * dir[0] + v->vu[1] * dir[1] + v->vu[2] * dir[2];
	for (int i = 0; i < 3; i++)
		up[i] = v->vu[i] - k * dir[i];
	unit(up);
	/* the picture's right is dir x up, so its left is up x dir */
	left[0] = up[1] * dir[2] - up[2] * dir[1];
	left[1] = up[2] * dir[0] - up[0] * dir[2];
	left[2] = up[0] * dir[1] - up[1] * dir[0];
}

/* World direction of polar angle theta and sensor azimuth phi (radians;
 * 0 = up, growing to the left) in the view. */
static void ps_dcpic_dir(const double f[3][3], double theta, double phi, double d[3])
{
	double st = sin(theta), ct = cos(theta), cp = cos(phi), sp = sin(phi);
	for (int i = 0; i < 3; i++)
		d[i] = ct * f[2][i] + st * (cp * f[0][i] + sp * f[1][i]);
}

int ps_dcpic_map(const struct ps_patches *P, const struct ps_view *v, int width, int height,
                 int *map, struct ps_err *e)
{
	struct ps_fisheye fe;
	double f[3][3];
	if (ps_view_check_fisheye(v, "coefficient pictures", e) != 0)
		return -1;
	if (width < 1 || height < 1)
		return ps_err_set(e, PS_EINVAL, "coefficient pictures: size %d x %d", width, height);
	ps_fisheye_init(&fe, v, width, height);
	ps_dcpic_frame(v, f);
	for (int row = 0; row < height; row++)
		for (int x = 0; x < width; x++) {
			double th, ph, d[3];
			int *m = &map[(size_t)row * (size_t)width + (size_t)x];
			if (ps_fisheye_pixel_dir(&fe, x, row, &th, &ph) != 0) {
				*m = -1;
				continue;
			}
			ps_dcpic_dir(f, th, ph, d);
			*m = ps_patches_find(P, d);
		}
	return 0;
}

static void init_picture(struct ps_picture *pic, int width, int height)
{
	memset(pic, 0, sizeof *pic);
	pic->width = width;
	pic->height = height;
	pic->format = PS_PIC_RGBE;
	pic->exposure[0] = pic->exposure[1] = pic->exposure[2] = PS_DCPIC_EXPOSURE;
	pic->pixaspect = 1.0;
}

int ps_dcpic_picture(const int *map, int width, int height, int patch, struct ps_picture *pic,
                     struct ps_err *e)
{
	size_t n = (size_t)width * (size_t)height;
	uint8_t one[4];
	const double white[3] = { 1.0, 1.0, 1.0 };
	init_picture(pic, width, height);
	pic->pix = calloc(n, 4);
	if (!pic->pix)
		return ps_err_set(e, PS_ENOMEM, "out of memory for a %d x %d picture", width, height);
	ps_picture_rgbe_encode(white, one);
	for (size_t i = 0; i < n; i++)
		if (map[i] == patch)
			memcpy(pic->pix + 4 * i, one, 4);
	return 0;
}

/* path_fmt with its one %d, %Nd or %0Nd replaced by p */
int ps_dcpic_path(const char *fmt, int p, char *out, size_t size, struct ps_err *e)
{
	const char *c = strchr(fmt, '%'), *q;
	int zero = 0, width = 0;
	if (!c)
		goto bad;
	q = c + 1;
	if (*q == '0') {
		zero = 1;
		q++;
	}
	while (*q >= '0' && *q <= '9' && width < 100)
		width = 10 * width + (*q++ - '0');
	if (*q != 'd' || strchr(q + 1, '%'))
		goto bad;
	if (zero)
		snprintf(out, size, "%.*s%0*d%s", (int)(c - fmt), fmt, width, p, q + 1);
	else
		snprintf(out, size, "%.*s%*d%s", (int)(c - fmt), fmt, width, p, q + 1);
	return 0;
bad:
	return ps_err_set(e, PS_EINVAL, "'%s' needs exactly one %%d (e.g. dc_%%03d.hdr)", fmt);
}

int ps_dcpic_write(const char *path_fmt, const struct ps_patches *P, const int *map, int width,
                   int height, const char *view, struct ps_err *e)
{
	size_t n = (size_t)width * (size_t)height;
	double *rgb = calloc(n * 3, sizeof *rgb);
	char extra[160];
	if (!rgb)
		return ps_err_set(e, PS_ENOMEM, "out of memory for a %d x %d picture", width, height);
	for (int p = 0; p < P->n; p++) {
		char path[4096];
		int rc;
		for (size_t i = 0; i < n; i++) {
			double v = map[i] == p ? 1.0 : 0.0;
			rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = v;
		}
		if (ps_dcpic_path(path_fmt, p, path, sizeof path, e) != 0) {
			free(rgb);
			return -1;
		}
		snprintf(extra, sizeof extra,
		         "daylight coefficient of sky patch %d of %d (MF %d): radiance 1 in the patch\n"
		         "EXPOSURE=%.8f\n",
		         p, P->n, P->mf, PS_DCPIC_EXPOSURE);
		rc = ps_picture_write(path, width, height, rgb, view, extra, e);
		if (rc != 0) {
			free(rgb);
			return -1;
		}
	}
	free(rgb);
	return 0;
}

int ps_dcpic_coefficients(const struct ps_weights *w, const int *map, int npatch,
                          const double coef[3], double *out, struct ps_err *e)
{
	/* one picture buffer: each patch's pixels set, integrated, cleared */
	size_t n = (size_t)w->width * (size_t)w->height, *first, *next;
	struct ps_picture pic;
	uint8_t one[4];
	const double white[3] = { 1.0, 1.0, 1.0 };
	int rc = 0;
	init_picture(&pic, w->width, w->height);
	pic.pix = calloc(n, 4);
	first = malloc((size_t)npatch * sizeof *first);
	next = malloc(n * sizeof *next);
	if (!pic.pix || !first || !next) {
		free(pic.pix);
		free(first);
		free(next);
		return ps_err_set(e, PS_ENOMEM, "out of memory for %d coefficient pictures", npatch);
	}
	ps_picture_rgbe_encode(white, one);
	/* each patch's pixels as a linked list */
	for (int p = 0; p < npatch; p++)
		first[p] = (size_t)-1;
	for (size_t i = n; i-- > 0;)
		if (map[i] >= 0 && map[i] < npatch) {
			next[i] = first[map[i]];
			first[map[i]] = i;
		}
	for (int p = 0; p < npatch && rc == 0; p++) {
		struct ps_response r;
		if (first[p] == (size_t)-1) {
			out[p] = 0.0;
			continue;
		}
		for (size_t i = first[p]; i != (size_t)-1; i = next[i])
			memcpy(pic.pix + 4 * i, one, 4);
		rc = ps_integrate(w, &pic, coef, &r, e);
		out[p] = r.response;
		for (size_t i = first[p]; i != (size_t)-1; i = next[i])
			memset(pic.pix + 4 * i, 0, 4);
	}
	free(pic.pix);
	free(first);
	free(next);
	return rc;
}
