/* SPDX-License-Identifier: ISC */
#include "calfit.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "errbuf.h"
#include "sum.h"

void psd_calfit_settle_init(struct psd_calfit_settle *s, double window, int min_n, double k, double floor)
{
	memset(s, 0, sizeof *s);
	s->window = window;
	s->min_n = min_n < 3 ? 3 : min_n > PSD_CALFIT_SETTLE_MAX ? PSD_CALFIT_SETTLE_MAX : min_n;
	s->k = k;
	s->floor = floor;
}

int psd_calfit_settle_add(struct psd_calfit_settle *s, double t, double v, double *mean, double *se)
{
	struct ps_sum st, sv, stt, stv, svv;
	double n, tm, vm, ctt, ctv, cvv, slope, resid_var, se_mean, span;
	int first = 0;
	if (!isfinite(v))
		return 0;
	if (s->n == PSD_CALFIT_SETTLE_MAX) {
		memmove(s->t, s->t + 1, (PSD_CALFIT_SETTLE_MAX - 1) * sizeof s->t[0]);
		memmove(s->v, s->v + 1, (PSD_CALFIT_SETTLE_MAX - 1) * sizeof s->v[0]);
		s->n--;
	}
	s->t[s->n] = t;
	s->v[s->n] = v;
	s->n++;
	/* the window: the last readings within `window` seconds */
	while (first < s->n - s->min_n && t - s->t[first] > s->window)
		first++;
	if (s->n - first < s->min_n)
		return 0;
	n = s->n - first;
	ps_sum_init(&st);
	ps_sum_init(&sv);
	for (int i = first; i < s->n; i++) {
		ps_sum_add(&st, s->t[i]);
		ps_sum_add(&sv, s->v[i]);
	}
	tm = ps_sum_get(&st) / n;
	vm = ps_sum_get(&sv) / n;
	ps_sum_init(&stt);
	ps_sum_init(&stv);
	ps_sum_init(&svv);
	for (int i = first; i < s->n; i++) {
		double dt = s->t[i] - tm, dv = s->v[i] - vm;
		ps_sum_add(&stt, dt * dt);
		ps_sum_add(&stv, dt * dv);
		ps_sum_add(&svv, dv * dv);
	}
	ctt = ps_sum_get(&stt);
	ctv = ps_sum_get(&stv);
	cvv = ps_sum_get(&svv);
	if (ctt <= 0)
		return 0;
	slope = ctv / ctt;
	resid_var = (cvv - slope * ctv) / (n - 2);
	if (resid_var < 0)
		resid_var = 0;
	se_mean = sqrt(resid_var / n);
	span = s->t[s->n - 1] - s->t[first];
	/* the trend across the window against the noise of its mean */
	if (fabs(slope) * span > s->k * se_mean + s->floor)
		return 0;
	*mean = vm;
	*se = sqrt(cvv / (n - 1) / n);
	return 1;
}

int psd_calfit_night(const struct psd_calfit_level *p, size_t n, struct psd_calfit_line *f, char *err, size_t errlen)
{
	struct ps_sum sw, swx, swy, sxx, sxy, syy;
	double w, xm, ym, cxx, cxy, cyy, chi2, full;
	size_t nlux = 0;
	int levels = 0;
	memset(f, 0, sizeof *f);
	f->lux_gain = f->lux_gain_se = f->lux_offset = NAN;
	if (n < 3)
		return psd_errbuf(err, errlen, "a night fit needs at least 3 levels (have %zu)", n);
	for (size_t i = 0; i < n; i++) {
		if (!isfinite(p[i].level) || !isfinite(p[i].volts))
			return psd_errbuf(err, errlen, "level %zu is not a number", i + 1);
		levels += i == 0 || p[i].level != p[0].level;
		nlux += isfinite(p[i].lux);
	}
	if (levels < 2)
		return psd_errbuf(err, errlen, "every point is at one level: the gain is undetermined");
	/* weights 1/se^2, with a floor so an exactly repeated reading (se 0)
	 * does not take all the weight */
	ps_sum_init(&sw);
	ps_sum_init(&swx);
	ps_sum_init(&swy);
	for (size_t i = 0; i < n; i++) {
		double se = fmax(p[i].volts_se, 1e-6);
		w = 1 / (se * se);
		ps_sum_add(&sw, w);
		ps_sum_add(&swx, w * p[i].level);
		ps_sum_add(&swy, w * p[i].volts);
	}
	xm = ps_sum_get(&swx) / ps_sum_get(&sw);
	ym = ps_sum_get(&swy) / ps_sum_get(&sw);
	ps_sum_init(&sxx);
	ps_sum_init(&sxy);
	ps_sum_init(&syy);
	for (size_t i = 0; i < n; i++) {
		double se = fmax(p[i].volts_se, 1e-6), dx = p[i].level - xm, dy = p[i].volts - ym;
		w = 1 / (se * se);
		ps_sum_add(&sxx, w * dx * dx);
		ps_sum_add(&sxy, w * dx * dy);
		ps_sum_add(&syy, w * dy * dy);
	}
	cxx = ps_sum_get(&sxx);
	cxy = ps_sum_get(&sxy);
	cyy = ps_sum_get(&syy);
	f->gain = cxy / cxx;
	f->offset = ym - f->gain * xm;
	chi2 = fmax(cyy - f->gain * cxy, 0);
	/* standard errors scaled by the fit's own scatter (reduced chi^2): the
	 * quoted se of each point may be too small or too large */
	{
		double scale = chi2 / (double)(n - 2);
		if (scale < 1)
			scale = 1;
		f->gain_se = sqrt(scale / cxx);
		f->offset_se = sqrt(scale * (1 / ps_sum_get(&sw) + xm * xm / cxx));
	}
	f->r2 = cyy > 0 ? 1 - chi2 / cyy : 1;
	full = fabs(f->offset + f->gain);
	for (size_t i = 0; i < n; i++) {
		double r = fabs(p[i].volts - (f->offset + f->gain * p[i].level));
		if (full > 0 && 100 * r / full > f->max_resid_pct)
			f->max_resid_pct = 100 * r / full;
	}
	if (nlux >= 3) {
		/* the ballast's light-output curve as the meter sees it: lux per unit */
		struct ps_sum a, b, c, d;
		double mx, my, kxx = 0, kxy = 0, res = 0, m = 0;
		ps_sum_init(&a);
		ps_sum_init(&b);
		for (size_t i = 0; i < n; i++)
			if (isfinite(p[i].lux)) {
				ps_sum_add(&a, p[i].level);
				ps_sum_add(&b, p[i].lux);
				m++;
			}
		mx = ps_sum_get(&a) / m;
		my = ps_sum_get(&b) / m;
		ps_sum_init(&c);
		ps_sum_init(&d);
		for (size_t i = 0; i < n; i++)
			if (isfinite(p[i].lux)) {
				ps_sum_add(&c, (p[i].level - mx) * (p[i].level - mx));
				ps_sum_add(&d, (p[i].level - mx) * (p[i].lux - my));
			}
		kxx = ps_sum_get(&c);
		kxy = ps_sum_get(&d);
		if (kxx > 0) {
			f->lux_gain = kxy / kxx;
			f->lux_offset = my - f->lux_gain * mx;
			for (size_t i = 0; i < n; i++)
				if (isfinite(p[i].lux)) {
					double r = p[i].lux - (f->lux_offset + f->lux_gain * p[i].level);
					res += r * r;
				}
			f->lux_gain_se = m > 2 ? sqrt(res / (m - 2) / kxx) : NAN;
		}
	}
	return 0;
}

int psd_calfit_day(const struct psd_calfit_sample *s, size_t n, double offset, double gain_e, double elec_lux,
                   double min_day_volts, struct psd_calfit_ratio *f, char *err, size_t errlen)
{
	struct ps_sum sr, srr, st;
	double m = 0, mean, var;
	memset(f, 0, sizeof *f);
	ps_sum_init(&sr);
	ps_sum_init(&st);
	for (size_t i = 0; i < n; i++) {
		double vd = s[i].volts - offset - gain_e * s[i].level, ed = s[i].lux - elec_lux * s[i].level;
		if (!isfinite(vd) || !isfinite(ed) || vd < min_day_volts || ed <= 0)
			continue;
		ps_sum_add(&sr, ed / vd);
		ps_sum_add(&st, s[i].t);
		m++;
	}
	if (m < 2)
		return psd_errbuf(err, errlen, "%g of %zu samples have daylight above %g V: at least 2 are needed", m,
		                n, min_day_volts);
	mean = ps_sum_get(&sr) / m;
	ps_sum_init(&srr);
	for (size_t i = 0; i < n; i++) {
		double vd = s[i].volts - offset - gain_e * s[i].level, ed = s[i].lux - elec_lux * s[i].level;
		if (!isfinite(vd) || !isfinite(ed) || vd < min_day_volts || ed <= 0)
			continue;
		ps_sum_add(&srr, (ed / vd - mean) * (ed / vd - mean));
	}
	var = ps_sum_get(&srr) / (m - 1);
	f->ratio = mean;
	f->sd = sqrt(var);
	f->ratio_se = sqrt(var / m);
	f->n = (size_t)m;
	f->mean_tod = ps_sum_get(&st) / m;
	return 0;
}

double psd_calfit_error_pct(double simulated, double measured)
{
	return 100 * (simulated - measured) / measured;
}

void psd_calfit_drift_init(struct psd_calfit_drift *d, double margin, double hold, double min_day_volts)
{
	memset(d, 0, sizeof *d);
	d->margin = margin;
	d->hold = hold;
	d->min_day_volts = min_day_volts;
	d->out_since = -1;
	d->last_ln = NAN;
}

int psd_calfit_drift_update(struct psd_calfit_drift *d, double now, double day_volts, double day_lux, double sim_ratio)
{
	double l, lux_as_volts, shown;
	if (!isfinite(day_volts) || !isfinite(day_lux) || !(sim_ratio > 0))
		return 0;
	/* Daylight must show in one of the two signals (in the sensor's units)
	 * to judge: a sensor covered completely (no daylight in its signal,
	 * plenty on the desk) is the drift most worth flagging.  Too dark to
	 * judge breaks a sustained excursion: at night, a small unknown sensor
	 * offset flickering across the threshold must not add up to an hour. */
	lux_as_volts = day_lux / sim_ratio;
	shown = fmax(day_volts, lux_as_volts);
	if (!(shown >= d->min_day_volts)) {
		d->out_since = -1;
		d->last_ln = NAN;   /* not judged: no drift figure for this sample */
		return 0;
	}
	/* a part at or below zero (noise, a covered sensor) is a ratio off by
	 * a factor of 1000 at most, so the log stays finite */
	l = log(fmax(lux_as_volts, 1e-3 * shown) / fmax(day_volts, 1e-3 * shown));
	d->last_ln = l;
	if (fabs(l) > d->margin) {
		if (d->out_since < 0)
			d->out_since = now;
		if (!d->flagged && now - d->out_since >= d->hold) {
			d->flagged = 1;
			return 1;
		}
		return 0;
	}
	d->out_since = -1;
	/* clears with hysteresis: back within half the margin */
	if (d->flagged && fabs(l) <= d->margin / 2) {
		d->flagged = 0;
		return -1;
	}
	return 0;
}
