/* SPDX-License-Identifier: ISC */
#include "cellmap.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fisheye.h"
#include "sum.h"

enum { MAX_THREADS = 8, CHUNK = 16 };

int ps_cellmap_fits(const struct ps_sensor *s, int method)
{
	if (method != PS_W_EXACT || s->kind != PS_SENS_TABLE || s->reading != PS_READ_CELL)
		return 0;
	for (int i = 0; i < s->ntheta; i++)
		for (int j = 1; j < s->nphi; j++)
			if (s->val[(size_t)i * (size_t)s->nphi + (size_t)j] != s->val[(size_t)i * (size_t)s->nphi])
				return 1;
	return 0;
}

struct job {
	const struct ps_sensor *s;
	struct ps_fisheye f;
	double rot;                      /* radians */
	const struct ps_weights *omega;
	const int *orun;                 /* top-based row -> omega's run, -1: none */
	struct ps_weights *w;
	const struct ps_weights_exact *ex;
	const double *radius;            /* plane radii of the circles (cells, table end, field) */
	int nradius;
	const double *ray_c, *ray_s;     /* the rays' directions in the plane */
	int nray;
	struct ps_sum *rowsum;           /* per run */
	size_t nexact;                   /* pixels that took the edge route */
	int next;
	int oom;
};

/* Mark the pixels of [x0, x1] (a run) whose closed u range meets [ua, ub]
 * (a millionth of a pixel wider on each side: a curve through a pixel
 * corner or along a pixel edge marks the pixels on both sides, whatever
 * the rounding of a, b). */
static void mark_u(const struct job *jb, unsigned char *mark, int x0, int x1, double ua, double ub)
{
	double du = jb->f.su / jb->f.width, a, b;
	int xa, xb;
	if (!(ua <= ub))
		return;
	a = (fmax(ua, -1e9) - jb->f.u0) / du;
	b = (fmin(ub, 1e9) - jb->f.u0) / du;
	xa = (int)floor(fmax(a, -2.0) - 1e-6);
	xb = (int)floor(fmin(b, (double)jb->f.width + 2.0) + 1e-6);
	if (xa < x0)
		xa = x0;
	if (xb > x1)
		xb = x1;
	for (int x = xa; x <= xb; x++)
		mark[x] = 1;
}

/* Mark the pixels of the run on row band [vb, vt] that a circle or a ray
 * may touch. */
static void mark_row(const struct job *jb, unsigned char *mark, int x0, int x1, double vb, double vt)
{
	double vmin = vb <= 0 && vt >= 0 ? 0.0 : fmin(fabs(vb), fabs(vt));
	double vmax = fmax(fabs(vb), fabs(vt));
	memset(mark + x0, 0, (size_t)(x1 - x0 + 1));
	for (int k = 0; k < jb->nradius; k++) {
		/* the circle meets the band where |u| = sqrt(R^2 - v^2), v in it */
		double r2 = jb->radius[k] * jb->radius[k], a, b;
		if (r2 < vmin * vmin)
			continue;
		a = sqrt(fmax(r2 - vmax * vmax, 0.0));
		b = sqrt(r2 - vmin * vmin);
		mark_u(jb, mark, x0, x1, a, b);
		mark_u(jb, mark, x0, x1, -b, -a);
	}
	for (int k = 0; k < jb->nray; k++) {
		/* the ray (t c, t s), t >= 0, inside the band */
		double c = jb->ray_c[k], s = jb->ray_s[k], t0, t1;
		if (s == 0.0) {
			if (vb <= 0 && vt >= 0)
				mark_u(jb, mark, x0, x1, c > 0 ? 0.0 : -1e9, c > 0 ? 1e9 : 0.0);
			continue;
		}
		t0 = (s > 0 ? vb : vt) / s;
		t1 = (s > 0 ? vt : vb) / s;
		if (t1 < 0)
			continue;
		t0 = fmax(t0, 0.0);
		mark_u(jb, mark, x0, x1, fmin(c * t0, c * t1), fmax(c * t0, c * t1));
	}
	if (vb <= 0 && vt >= 0)
		mark_u(jb, mark, x0, x1, 0.0, 0.0);   /* the zenith */
}

/* The cell value at the centre of pixel x on bottom-based row j. */
static double cell_value(const struct job *jb, int x, int j)
{
	const struct ps_sensor *s = jb->s;
	double uc = ps_fisheye_u(&jb->f, x + 0.5), vc = ps_fisheye_v(&jb->f, j + 0.5);
	double theta = ps_fisheye_theta(&jb->f, hypot(uc, vc));
	double phi = atan2(vc, uc) - M_PI / 2 - jb->rot;
	int i, k;
	ps_sensor_locate(s, theta, &phi, &i, &k);
	return i >= s->nt ? 0.0 : s->val[(size_t)i * (size_t)s->nphi + (size_t)k];
}

/* A thread's rows, CHUNK runs (consecutive rows, bottom up) at a time.
 * The exact pixels share their edges: a vertical one with the marked
 * neighbour on its left, the bottom one with the marked pixel below when
 * the row below was done here just before. */
struct rowbuf {
	unsigned char *mark[2];
	double *htop[2];
	int x0[2], x1[2];
};

static void *fill_run(void *arg)
{
	struct job *jb = arg;
	struct ps_weights *w = jb->w;
	size_t wd = (size_t)jb->f.width + 1, nexact = 0;
	struct rowbuf b;
	b.mark[0] = malloc(2 * wd);
	b.htop[0] = malloc(2 * wd * sizeof(double));
	if (!b.mark[0] || !b.htop[0]) {
		free(b.mark[0]);
		free(b.htop[0]);
		__atomic_store_n(&jb->oom, 1, __ATOMIC_RELAXED);
		return NULL;
	}
	b.mark[1] = b.mark[0] + wd;
	b.htop[1] = b.htop[0] + wd;
	for (;;) {
		size_t r0 = (size_t)__atomic_fetch_add(&jb->next, CHUNK, __ATOMIC_RELAXED);
		int prev_j = -2;   /* the bottom-based row done last here (its marks in b.*[1 - cur]) */
		int cur = 0;
		if (r0 >= w->nruns)
			break;
		for (size_t ri = r0; ri < r0 + CHUNK && ri < w->nruns; ri++) {
			const struct ps_weights_run *run = &w->runs[ri];
			int j = w->height - 1 - run->row, x0 = run->x0, x1 = run->x0 + run->n - 1;
			int oi = jb->orun[run->row], below = prev_j == j - 1, prev_x = -2;
			const struct ps_weights_run *orun = oi >= 0 ? &jb->omega->runs[oi] : NULL;
			unsigned char *mark = b.mark[cur], *mark_b = b.mark[1 - cur];
			double *ht = b.htop[cur], *hb_prev = b.htop[1 - cur];
			double *out = w->w + run->off, vright = 0.0;
			struct ps_sum rs;   /* local: the stores to out cannot alias it */
			mark_row(jb, mark, x0, x1, ps_fisheye_v(&jb->f, j), ps_fisheye_v(&jb->f, j + 1));
			ps_sum_init(&rs);
			for (int x = x0; x <= x1;) {
				double wt;
				if (!orun || x < orun->x0 || x >= orun->x0 + orun->n)
					mark[x] = 1;   /* no solid angle to scale: the edge route */
				if (mark[x]) {
					double hb, vl;
					hb = below && x >= b.x0[1 - cur] && x <= b.x1[1 - cur] && mark_b[x]
					         ? hb_prev[x]
					         : ps_weights_exact_hedge(jb->ex, x, j);
					ht[x] = ps_weights_exact_hedge(jb->ex, x, j + 1);
					vl = prev_x == x - 1 ? vright : ps_weights_exact_vedge(jb->ex, x, j);
					vright = ps_weights_exact_vedge(jb->ex, x + 1, j);
					prev_x = x;
					wt = ps_weights_exact_pixel(hb, vright, ht[x], vl);
					nexact++;
					out[x - x0] = wt;
					ps_sum_add(&rs, wt);
					x++;
				} else {
					/* a stretch of unmarked pixels: neighbours that share an
					 * edge inside one cell, so all in the first one's cell */
					int xe = x, o0 = orun->x0, oe = orun->x0 + orun->n;
					double sens = cell_value(jb, x, j), lane[4] = { 0, 0, 0, 0 };
					while (xe < x1 && xe + 1 < oe && !mark[xe + 1])
						xe++;
					/* four lanes of plain sums (one sign, at most a row's
					 * pixels: each within 1e-13), then one compensated add */
					for (int q = x; q <= xe; q++) {
						double wq = sens * ps_weights_run_at(jb->omega, orun, q - o0);
						out[q - x0] = wq;
						lane[(q - x) & 3] += wq;
					}
					ps_sum_add(&rs, (lane[0] + lane[1]) + (lane[2] + lane[3]));
					x = xe + 1;
				}
			}
			jb->rowsum[ri] = rs;
			b.x0[cur] = x0;
			b.x1[cur] = x1;
			prev_j = j;
			cur = 1 - cur;
		}
	}
	free(b.mark[0]);
	free(b.htop[0]);
	__atomic_fetch_add(&jb->nexact, nexact, __ATOMIC_RELAXED);
	return NULL;
}

int ps_cellmap_build(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                     const struct ps_view *v, int width, int height,
                     const struct ps_weights *omega, struct ps_err *e)
{
	struct job jb;
	struct ps_weights_exact *ex = NULL;
	double *radius = NULL, *ray = NULL;
	int *orun = NULL, nthreads = 1, started = 0;
	pthread_t tid[MAX_THREADS];
	struct ps_sum total;
	if (!ps_cellmap_fits(s, PS_W_EXACT))
		return ps_err_set(e, PS_EINVAL, "%s: not a cell-reading table that changes with azimuth",
		                  s->path ? s->path : "sensor");
	if (omega->width != width || omega->height != height || omega->method != PS_W_EXACT)
		return ps_err_set(e, PS_EINVAL, "solid-angle map of %d x %d for %d x %d weights",
		                  omega->width, omega->height, width, height);
	if (ps_weights_layout(w, s, rotation_deg, v, width, height, e) != 0)
		return -1;
	memset(&jb, 0, sizeof jb);
	jb.s = s;
	jb.rot = rotation_deg * M_PI / 180.0;
	jb.omega = omega;
	jb.w = w;
	ps_fisheye_init(&jb.f, v, width, height);
	radius = malloc(((size_t)s->nt + 2) * sizeof *radius);
	ray = malloc(2 * ((size_t)s->np + 1) * sizeof *ray);
	orun = malloc((size_t)height * sizeof *orun);
	if (!radius || !ray || !orun)
		goto oom;
	for (int i = 1; i <= s->nt; i++)
		if (s->tb[i] < jb.f.theta_field)
			radius[jb.nradius++] = ps_fisheye_rho(&jb.f, s->tb[i]);
	radius[jb.nradius++] = 1.0;   /* the field's edge */
	for (int k = 0; k < s->np; k++) {
		double a = s->pb[k] + M_PI / 2 + jb.rot;
		ray[k] = cos(a);
		ray[s->np + 1 + k] = sin(a);
	}
	jb.radius = radius;
	jb.ray_c = ray;
	jb.ray_s = ray + s->np + 1;
	jb.nray = s->np;
	for (int y = 0; y < height; y++)
		orun[y] = -1;
	for (size_t k = 0; k < omega->nruns; k++)
		if (omega->runs[k].row >= 0 && omega->runs[k].row < height)
			orun[omega->runs[k].row] = (int)k;
	jb.orun = orun;
	jb.rowsum = malloc((w->nruns ? w->nruns : 1) * sizeof *jb.rowsum);
	if (!jb.rowsum)
		goto oom;
	if (ps_weights_exact_open(&ex, s, rotation_deg, v, width, height, e) != 0)
		goto fail;
	jb.ex = ex;
	if (w->nw > 8192) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nthreads = n < 1 ? 1 : n > MAX_THREADS ? MAX_THREADS : (int)n;
	}
	for (int t = 1; t < nthreads; t++)
		if (pthread_create(&tid[t], NULL, fill_run, &jb) == 0)
			started |= 1 << t;
	fill_run(&jb);
	for (int t = 1; t < nthreads; t++)
		if (started & (1 << t))
			pthread_join(tid[t], NULL);
	if (jb.oom)
		goto oom;
	ps_sum_init(&total);
	for (size_t ri = 0; ri < w->nruns; ri++)
		ps_sum_merge(&total, &jb.rowsum[ri]);
	w->sens_sum = ps_sum_get(&total);
	w->coverage = w->sens_full > 0 ? w->sens_sum / w->sens_full : 0.0;
	ps_weights_exact_close(ex);
	free(jb.rowsum);
	free(radius);
	free(ray);
	free(orun);
	return 0;
oom:
	ps_err_set(e, PS_ENOMEM, "out of memory building %d x %d weights", width, height);
fail:
	ps_weights_exact_close(ex);
	free(jb.rowsum);
	free(radius);
	free(ray);
	free(orun);
	ps_weights_free(w);
	return -1;
}
