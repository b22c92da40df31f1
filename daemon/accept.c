/* SPDX-License-Identifier: ISC */
/* Acceptance tests from the sample log (see accept.h). */
#include "accept.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "db.h"
#include "sum.h"

const char *const psd_accept_verdict_names[] = { "NOT TESTED", "FAIL", "PASS" };

void psd_accept_defaults(struct psd_accept_params *p)
{
	*p = (struct psd_accept_params){ 500, NAN, 300, NAN, 10, 25, 30, 0.05, PSD_ACCEPT_SETTLE_S, NAN, NAN };
}

/* The spans calibration sessions held the zone's lights, each in UTC
 * (NAN when the session was logged before schema 5) and on the daemon's
 * clock; a sample is compared in UTC when both carry it. */
struct held {
	double (*span)[4];        /* UTC from, to; clock from, to */
	size_t n, cap;
	double settle;            /* s after each span's end still held */
	long left_out;            /* samples the spans and their settling left out */
	int failed;               /* out of memory: the run fails, no verdict */
};

/* The UTC of each start of psensd: a new run's lights start from its own
 * initial level, so no step crosses one. */
struct starts {
	double *utc;
	size_t n, cap, next;
	int failed;
};

struct scan {
	const struct psd_accept_params *p;
	struct held held;
	struct starts starts;
	double last_t;            /* the previous sample's clock time (NAN: none) */
	/* verification */
	struct ps_sum e2;
	long n;
	double worst, worst_at;
	char worst_local[17];     /* "YYYY-MM-DD HH:MM" of the worst, "" when not dated */
	long band[3];
	/* full daylight */
	long nfull;
	double full_max;
	/* low daylight */
	long nlow;
	double low_min;
	/* the output the lights were at when a sample's readings were taken:
	 * the one commanded at the step before (NAN: none yet) */
	double prev_output;
	/* cycling */
	double last_level, last_swing_t, min_gap;
	int last_dir;
	long swings, fast;
	/* occupancy: the last sample's occupancy (-1 none), the vacancy's start
	 * and its state (0 none or not judged, 1 within the hold, 2 judged) */
	int occ_prev, vac_state, have_occ;
	double vac_from, vac_delay_max;
	long nvac, vac_fail, narr, arr_fail;
	long vacant;              /* samples the occupancy said vacant: no daylight test judges them */
};

/* arr (n elements of size, room for *cap) with room for one more,
 * doubling; NULL when out of memory, arr as it was. */
static void *grow(void *arr, size_t n, size_t *cap, size_t size)
{
	size_t c = *cap ? 2 * *cap : 8;
	void *q;
	if (n < *cap)
		return arr;
	if ((q = realloc(arr, c * size)))
		*cap = c;
	return q;
}

static void add_session(void *user, const struct psd_db_cal_session *s)
{
	struct held *h = user;
	double *sp;
	void *q = grow(h->span, h->n, &h->cap, sizeof *h->span);
	if (!q) {
		h->failed = 1;
		return;
	}
	h->span = q;
	/* a session still running (or killed) has held the lights since it started */
	sp = h->span[h->n++];
	sp[0] = s->started_utc;
	sp[1] = isfinite(s->started_utc) && isnan(s->ended_utc) ? INFINITY : s->ended_utc;
	sp[2] = s->started;
	sp[3] = isfinite(s->started) && isnan(s->ended) ? INFINITY : s->ended;
}

static int is_held(const struct held *h, const struct psd_sample *s)
{
	for (size_t i = 0; i < h->n; i++) {
		int utc = isfinite(s->utc) && isfinite(h->span[i][0]);
		double t = utc ? s->utc : s->t;
		const double *sp = h->span[i] + (utc ? 0 : 2);
		if (t >= sp[0] && t <= sp[1] + h->settle)
			return 1;
	}
	return 0;
}

static void add_start(void *user, double utc)
{
	struct starts *st = user;
	void *q = grow(st->utc, st->n, &st->cap, sizeof *st->utc);
	if (!q) {
		st->failed = 1;
		return;
	}
	st->utc = q;
	st->utc[st->n++] = utc;
}

/* 1 when s is the first sample of a run after another: a start on record
 * since the previous sample, or (rows logged before dates) the clock gone
 * back. */
static int new_run(struct scan *c, const struct psd_sample *s)
{
	int fresh = isfinite(c->last_t) && s->t < c->last_t;
	while (isfinite(s->utc) && c->starts.next < c->starts.n && s->utc >= c->starts.utc[c->starts.next]) {
		c->starts.next++;
		fresh = 1;
	}
	c->last_t = s->t;
	return fresh;
}

/* cycling: swings of the commanded output, each against the last one's
 * direction, and how far apart on the run's clock (it runs on over
 * midnight; no swing crosses a run, new_run) */
static void track_cycling(struct scan *c, const struct psd_sample *s)
{
	const struct psd_accept_params *p = c->p;
	if (isnan(c->last_level)) {
		c->last_level = s->output;
	} else if (fabs(s->output - c->last_level) > p->swing) {
		int dir = s->output > c->last_level ? 1 : -1;
		if (c->last_dir != 0 && dir != c->last_dir) {
			double gap = s->t - c->last_swing_t;
			c->swings++;
			if (gap < c->min_gap)
				c->min_gap = gap;
			if (gap < p->delay)
				c->fast++;
		}
		if (dir != c->last_dir)
			c->last_swing_t = s->t;
		c->last_dir = dir;
		c->last_level = s->output;
	}
}

/* occupancy: each vacancy's first sample at or after its start plus the
 * hold, and each arrival's sample (accept.h) */
static void track_occupancy(struct scan *c, const struct psd_sample *s, int spoiled)
{
	const struct psd_accept_params *p = c->p;
	int occ = s->occupied;
	if (occ < 0) {
		c->occ_prev = -1;
		c->vac_state = 0;
		return;
	}
	c->have_occ = 1;
	if (occ == 0) {
		if (c->occ_prev != 0) {   /* a vacancy starts (or the log with one) */
			c->vac_from = s->t;
			c->vac_state = 1;
		}
		if (spoiled)
			c->vac_state = 0;   /* a fault or a session: the lights were not the vacancy's */
		if (c->vac_state == 1 && s->t >= c->vac_from + p->vacancy_hold) {
			c->nvac++;
			if (s->output <= p->vacant_level + 1e-6) {
				if (s->t - c->vac_from > c->vac_delay_max)
					c->vac_delay_max = s->t - c->vac_from;
			} else {
				c->vac_fail++;
			}
			c->vac_state = 2;
		}
	} else if (c->occ_prev == 0 && !spoiled && p->vacant_level <= 0) {
		c->narr++;   /* an arrival: the lights come on */
		c->arr_fail += !(s->output > 0);
	}
	c->occ_prev = occ;
}

static void scan_sample(void *user, const struct psd_sample *s)
{
	struct scan *c = user;
	const struct psd_accept_params *p = c->p;
	double dl, prev;
	int held;
	if (new_run(c, s)) {
		c->prev_output = NAN;  /* the lights' level before a run's first sample is not known */
		c->last_level = NAN;   /* nor is its first level an answer to the last run's */
		c->last_dir = 0;
		c->occ_prev = -1;      /* a run's hold starts at its start */
	}
	if (isfinite(p->since_utc) && !(s->utc >= p->since_utc))
		return;
	if (isfinite(p->vacancy_hold))
		track_occupancy(c, s, s->fault || !isfinite(s->output) || is_held(&c->held, s));
	if (s->occupied == 0 && !s->fault && isfinite(s->output)) {
		/* vacant: the lights are the vacancy's, not the daylight
		 * control's (an empty dark room's few lux judge nothing); the
		 * control starts again at the arrival */
		c->prev_output = s->output;
		c->last_level = NAN;
		c->last_dir = 0;
		c->vacant++;
		return;
	}
	if (s->fault || !isfinite(s->output)) {
		c->prev_output = NAN;   /* at the safe level: the next sample has no known level */
		return;
	}
	/* a calibration session held the lights, or its level is fading into
	 * the control's: the sample judges neither the control nor its
	 * estimate (readings at one level, the estimate made for another) */
	held = is_held(&c->held, s);
	if (held) {
		c->last_level = NAN;   /* the control starts again from wherever the session left it */
		c->last_dir = 0;
		c->prev_output = s->output;
		c->held.left_out++;
		return;
	}
	track_cycling(c, s);
	/* a sample's readings were taken with the lights at the previous step's
	 * output; its output is the control's answer to them */
	prev = c->prev_output;
	c->prev_output = s->output;
	if (isnan(prev) || !(s->task_lux > 0) || !isfinite(p->elec_task_lux) || !(p->target_lux > 0))
		return;
	dl = (s->task_lux - p->elec_task_lux * prev) / p->target_lux;
	if (isfinite(s->est_task_lux)) {
		double e = (s->est_task_lux - s->task_lux) / s->task_lux;
		ps_sum_add(&c->e2, e * e);
		c->n++;
		if (fabs(e) > c->worst) {
			c->worst = fabs(e);
			c->worst_at = s->tod_s;
			snprintf(c->worst_local, sizeof c->worst_local, "%s", s->local ? s->local : "");
		}
		c->band[dl < 0.5 ? 0 : dl < 1.5 ? 1 : 2]++;
	}
	if (dl >= 1.5) {
		c->nfull++;
		if (s->output > c->full_max)
			c->full_max = s->output;
	} else if (dl < 0.1) {
		c->nlow++;
		if (s->task_lux < c->low_min)
			c->low_min = s->task_lux;
	}
}

static void occupancy_result(const struct scan *c, struct psd_accept_result *r)
{
	const struct psd_accept_params *p = c->p;
	char arr[160];
	int hold_ok = p->vacancy_hold <= PSD_ACCEPT_HOLD_MAX_S;
	r->test = "occupancy";
	r->samples = c->nvac + c->narr;
	r->limit = p->vacancy_hold;
	r->unit = "s";
	r->bound = "by the first step after";
	r->value = c->nvac ? c->vac_delay_max : NAN;
	if (p->vacant_level > 0)
		snprintf(arr, sizeof arr, "arrivals not judged (a partial off at %.0f %%: the daylight control may "
		         "ask less)", 100 * p->vacant_level);
	else
		snprintf(arr, sizeof arr, "the lights on at %ld of %ld arrivals", c->narr - c->arr_fail, c->narr);
	if (c->nvac + c->narr == 0) {
		r->verdict = PSD_ACCEPT_NOT_TESTED;
		snprintf(r->measured, sizeof r->measured, "no vacancy longer than the hold (%g s) and no arrival",
		         p->vacancy_hold);
		return;
	}
	r->verdict = hold_ok && !c->vac_fail && !c->arr_fail ? PSD_ACCEPT_PASS : PSD_ACCEPT_FAIL;
	snprintf(r->measured, sizeof r->measured, "at the vacant level %.0f %% by the first step after the hold "
	         "(%g s, at most %g s) in %ld of %ld vacancies that outlasted it (the latest %.0f s after the "
	         "vacancy); %s", 100 * p->vacant_level, p->vacancy_hold, PSD_ACCEPT_HOLD_MAX_S, c->nvac - c->vac_fail,
	         c->nvac, c->nvac ? c->vac_delay_max : 0, arr);
}

int psd_accept_run(struct psd_db *db, const char *zone, const struct psd_accept_params *p,
                   struct psd_accept_result out[PSD_ACCEPT_NTESTS], char *err, size_t errlen)
{
	struct scan c;
	struct psd_accept_result *r;
	char left[160];
	int bands;
	memset(&c, 0, sizeof c);
	c.p = p;
	ps_sum_init(&c.e2);
	c.last_level = NAN;
	c.prev_output = NAN;
	c.full_max = -INFINITY;
	c.low_min = INFINITY;
	c.min_gap = INFINITY;
	c.occ_prev = -1;
	c.held.settle = isfinite(p->settle_s) && p->settle_s > 0 ? p->settle_s : 0;
	if (psd_db_cal_sessions(db, zone, add_session, &c.held, err, errlen) != 0) {
		free(c.held.span);
		return -1;
	}
	if (c.held.failed) {
		free(c.held.span);
		snprintf(err, errlen, "zone %s: the calibration sessions: out of memory", zone);
		return -1;
	}
	c.last_t = NAN;
	if (psd_db_run_starts(db, add_start, &c.starts, err, errlen) != 0 || c.starts.failed) {
		if (c.starts.failed)
			snprintf(err, errlen, "zone %s: the starts on record: out of memory", zone);
		free(c.held.span);
		free(c.starts.utc);
		return -1;
	}
	if (psd_db_zone_samples(db, zone, scan_sample, &c, err, errlen) != 0) {
		free(c.held.span);
		free(c.starts.utc);
		return -1;
	}
	free(c.held.span);
	free(c.starts.utc);
	memset(out, 0, PSD_ACCEPT_NTESTS * sizeof *out);
	bands = (c.band[0] > 0) + (c.band[1] > 0) + (c.band[2] > 0);
	if (c.held.left_out)
		snprintf(left, sizeof left, "; %ld samples in %zu calibration session%s and the %g s after each left out",
		         c.held.left_out, c.held.n, c.held.n == 1 ? "" : "s", c.held.settle);
	else
		left[0] = 0;
	if (c.vacant) {
		size_t k = strlen(left);
		snprintf(left + k, sizeof left - k, "; %ld vacant samples left out", c.vacant);
	}

	r = &out[0];
	r->test = "verification";
	r->samples = c.n;
	r->left_out = c.held.left_out;
	r->settle_s = c.held.settle;
	r->value = c.n ? 100 * sqrt(ps_sum_get(&c.e2) / (double)c.n) : NAN;
	r->limit = p->rms_max;
	r->unit = "%";
	r->bound = "at most";
	if (c.n == 0) {
		r->verdict = PSD_ACCEPT_NOT_TESTED;
		snprintf(r->measured, sizeof r->measured, "no sample with a task meter reading and an estimate");
	} else {
		int ok = c.n >= p->min_samples && bands >= 2 && r->value <= p->rms_max && 100 * c.worst <= p->worst_max;
		r->verdict = ok ? PSD_ACCEPT_PASS : PSD_ACCEPT_FAIL;
		char when[20];
		/* a record spans days: the worst sample's date with its time */
		if (strlen(c.worst_local) == 16)
			snprintf(when, sizeof when, "%s", c.worst_local);
		else
			psd_clock_hhmm(c.worst_at, when);
		snprintf(r->measured, sizeof r->measured, "estimate against the meter over %ld samples (at least %ld): "
		         "rms %.2f %% (at most %g %%), worst %.2f %% at %s (at most %g %%); daylight at the "
		         "task below 50 %% of the target in %ld, 50-150 %% in %ld, 150 %% and more in %ld (two bands "
		         "at least)%s", c.n, p->min_samples, r->value, p->rms_max, 100 * c.worst, when, p->worst_max,
		         c.band[0], c.band[1], c.band[2], left);
	}

	r = &out[1];
	r->test = "full daylight";
	r->samples = c.nfull;
	r->limit = 35;
	r->value = c.nfull ? 100 * c.full_max : NAN;
	r->unit = "%";   /* of full output */
	r->bound = "at most";
	if (!c.nfull) {
		r->verdict = PSD_ACCEPT_NOT_TESTED;
		snprintf(r->measured, sizeof r->measured, "no sample with daylight at the task at 150 %% of the "
		         "target (%g lx) or more", 1.5 * p->target_lux);
	} else {
		r->verdict = r->value <= 35 + 1e-9 ? PSD_ACCEPT_PASS : PSD_ACCEPT_FAIL;
		snprintf(r->measured, sizeof r->measured, "with daylight at the task at 150 %% of %g lx or more "
		         "(%ld samples) the light output was at most %.1f %% (at most 35 %%)", p->target_lux, c.nfull,
		         r->value);
	}

	r = &out[2];
	r->test = "low daylight";
	r->samples = c.nlow;
	r->limit = 90;
	r->value = c.nlow ? 100 * c.low_min / p->target_lux : NAN;
	r->unit = "%";   /* of the target */
	r->bound = "at least";
	if (!c.nlow) {
		r->verdict = PSD_ACCEPT_NOT_TESTED;
		snprintf(r->measured, sizeof r->measured, "no sample with daylight at the task below 10 %% of the "
		         "target");
	} else {
		r->verdict = r->value >= 90 - 1e-9 ? PSD_ACCEPT_PASS : PSD_ACCEPT_FAIL;
		snprintf(r->measured, sizeof r->measured, "with daylight below 10 %% of the target (%ld samples) "
		         "the task was at least %.0f lx, %.1f %% of %g lx (at least 90 %%)", c.nlow, c.low_min,
		         r->value, p->target_lux);
	}

	r = &out[3];
	r->test = "cycling";
	r->samples = c.swings;
	r->limit = p->delay;
	r->value = c.swings ? c.min_gap : NAN;
	r->unit = "s";
	r->bound = "at least";
	r->verdict = c.fast ? PSD_ACCEPT_FAIL : PSD_ACCEPT_PASS;
	if (c.swings)
		snprintf(r->measured, sizeof r->measured, "%ld reversal%s of the output by more than %.0f %%, the "
		         "closest %.0f s apart, %ld within the %g s delay", c.swings, c.swings == 1 ? "" : "s",
		         100 * p->swing, c.min_gap, c.fast, p->delay);
	else
		snprintf(r->measured, sizeof r->measured, "no reversal of the output by more than %.0f %%",
		         100 * p->swing);

	if (c.have_occ)
		occupancy_result(&c, &out[4]);
	return 0;
}

int psd_accept_option(struct psd_accept_params *p, const char *opt, const char *val, char *err, size_t errlen)
{
	char *end;
	if (strcmp(opt, "--since") == 0) {
		if (psd_clock_parse_date(val, &p->since_utc) != 0) {
			snprintf(err, errlen, "accept-test --since %s: not a date YYYY-MM-DD", val);
			return -1;
		}
		return 1;
	}
	if (strcmp(opt, "--samples") == 0) {
		p->min_samples = strtol(val, &end, 10);
		if (*end || p->min_samples < 1) {
			snprintf(err, errlen, "accept-test --samples %s: a count from 1", val);
			return -1;
		}
		return 1;
	}
	return 0;
}

void psd_accept_summarize(const struct psd_accept_result r[PSD_ACCEPT_NTESTS], struct psd_accept_summary *sum)
{
	memset(sum, 0, sizeof *sum);
	for (int i = 0; i < PSD_ACCEPT_NTESTS; i++) {
		if (!r[i].test)
			continue;
		sum->count++;
		sum->failed += r[i].verdict == PSD_ACCEPT_FAIL;
		sum->tested += r[i].verdict != PSD_ACCEPT_NOT_TESTED;
	}
}

const char *psd_accept_overall(const struct psd_accept_summary *sum)
{
	return sum->failed ? "NOT ACCEPTED" : sum->tested == sum->count ? "ACCEPTED" : "INCOMPLETE";
}

int psd_accept_verification(struct psd_db *db, const char *zone, struct psd_accept_result *r, char *err,
                            size_t errlen)
{
	struct psd_accept_params p;
	struct psd_accept_result out[PSD_ACCEPT_NTESTS];
	psd_accept_defaults(&p);
	if (psd_db_zone_consts_get(db, zone, &p.target_lux, &p.elec_task_lux, &p.delay) != 0) {
		snprintf(err, errlen, "zone %s: no design constants on record (psensd records them when it starts)",
		         zone);
		return -1;
	}
	psd_db_zone_occupancy_get(db, zone, &p.vacancy_hold, &p.vacant_level);
	if (psd_accept_run(db, zone, &p, out, err, errlen) != 0)
		return -1;
	*r = out[0];
	return 0;
}

int psd_accept_zone(struct psd_db *db, const char *zone, struct psd_accept_params *p, double utc,
                    struct psd_accept_result out[PSD_ACCEPT_NTESTS], struct psd_accept_summary *sum, char *err,
                    size_t errlen)
{
	char why[256];
	int found = psd_db_zone_consts_get(db, zone, &p->target_lux, &p->elec_task_lux, &p->delay);
	memset(sum, 0, sizeof *sum);
	memset(out, 0, PSD_ACCEPT_NTESTS * sizeof *out);
	if (found != 0 || psd_db_zone_count(db, zone, why, sizeof why) <= 0) {
		snprintf(err, errlen, "no zone '%s' on record%s", zone,
		         found != 0 ? " (psensd records a zone's design constants when it starts)" : "");
		return -1;
	}
	if (!isfinite(p->vacancy_hold))   /* a caller's own constants stand */
		psd_db_zone_occupancy_get(db, zone, &p->vacancy_hold, &p->vacant_level);
	if (psd_accept_run(db, zone, p, out, err, errlen) != 0)
		return -1;
	psd_accept_summarize(out, sum);
	for (int i = 0; i < PSD_ACCEPT_NTESTS; i++)
		if (out[i].test && psd_db_accept_add(db, zone, utc, out[i].test, psd_accept_verdict_names[out[i].verdict + 1],
		                      out[i].value, out[i].limit, out[i].samples, out[i].measured, err, errlen) != 0) {
			sum->unstored = 1;
			return -1;
		}
	return 0;
}
