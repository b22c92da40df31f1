/* SPDX-License-Identifier: ISC */
/* Calibration arithmetic: pure functions, each tested against analytic
 * answers (tests/unit/test_calfit.c).
 *
 *   settling   when has a reading stopped moving?  A window of the last
 *              readings is fitted with a line; the reading has settled when
 *              the line's change across the window is within k standard
 *              errors of the window's mean (plus an absolute floor).
 *   night      volts at several light outputs u with no daylight:
 *              V = offset + gain_e u by weighted least squares, with the
 *              standard errors of both, R^2 and the worst residual.
 *   day        volts V and task lux E at a known output u: the daylight
 *              parts V_d = V - offset - gain_e u and E_d = E - E_E u, their
 *              ratio E_d / V_d (lux per volt, the paper's Table 1) with its
 *              standard error, and its error against the simulation
 *              100 (simulated - measured) / measured (the paper's Table 2).
 *   drift      the measured ratio against the simulated one over time:
 *              flagged when |ln(measured / simulated)| stays above a margin
 *              for a hold time, judged while daylight shows in the sensor's
 *              signal or on the task (a covered sensor is drift too); a
 *              sample too dark to judge ends a sustained excursion. */
#ifndef PSD_CALFIT_H
#define PSD_CALFIT_H

#include <stddef.h>

enum { PSD_CALFIT_SETTLE_MAX = 64 };

struct psd_calfit_settle {
	double window;            /* seconds of readings judged together */
	int min_n;                /* at least this many readings */
	double k;                 /* change allowed, in standard errors of the mean */
	double floor;             /* change always allowed (volts): quantisation */
	double t[PSD_CALFIT_SETTLE_MAX], v[PSD_CALFIT_SETTLE_MAX];
	int n;
};

void psd_calfit_settle_init(struct psd_calfit_settle *s, double window, int min_n, double k, double floor);
/* Add a reading; 1 when settled (mean and its standard error out), else 0. */
int psd_calfit_settle_add(struct psd_calfit_settle *s, double t, double v, double *mean, double *se);

struct psd_calfit_level {
	double level;             /* light output 0..1 */
	double volts, volts_se;   /* settled mean and its standard error */
	double lux;               /* task lux (NAN without a meter) */
};

struct psd_calfit_line {
	double offset, offset_se; /* volts with the lights off */
	double gain, gain_se;     /* volts per unit of light output (S_E, at full output) */
	double r2;
	double max_resid_pct;     /* worst |residual| as % of the full-output signal */
	double lux_gain, lux_gain_se; /* task lux per unit output (E_E), NAN without a meter */
	double lux_offset;
};

/* -1 with a message when the points cannot determine a line (fewer than 3,
 * one level only, non-finite values). */
int psd_calfit_night(const struct psd_calfit_level *p, size_t n, struct psd_calfit_line *f, char *err, size_t errlen);

struct psd_calfit_sample {
	double t;                 /* time of day, s */
	double level, volts, lux;
};

struct psd_calfit_ratio {
	double ratio, ratio_se;   /* measured daylight lux per daylight volt */
	double sd;                /* spread of the per-sample ratios */
	size_t n;                 /* samples used (enough daylight) */
	double mean_tod;          /* their mean time of day */
};

/* The measured ratio from samples, with the night fit's offset and gain_e
 * and the electric task lux per unit output elec_lux.  Samples whose
 * daylight volts are below min_day_volts are left out.  -1 with a message
 * when fewer than 2 remain. */
int psd_calfit_day(const struct psd_calfit_sample *s, size_t n, double offset, double gain_e, double elec_lux,
                   double min_day_volts, struct psd_calfit_ratio *f, char *err, size_t errlen);
/* 100 (simulated - measured) / measured. */
double psd_calfit_error_pct(double simulated, double measured);

struct psd_calfit_drift {
	double margin;            /* |ln(measured/simulated)| above this is out */
	double hold;              /* seconds out before it is drift */
	double min_day_volts;     /* less daylight than this in both signals (task lux as volts): no judgement */
	double out_since;         /* -1: in */
	int flagged;
	double last_ln;           /* the last ln(measured/simulated) judged */
};

void psd_calfit_drift_init(struct psd_calfit_drift *d, double margin, double hold, double min_day_volts);
/* Judge one sample: returns +1 when drift is flagged now, -1 when it clears
 * now, 0 otherwise. */
int psd_calfit_drift_update(struct psd_calfit_drift *d, double now, double day_volts, double day_lux,
                            double sim_ratio);

#endif
