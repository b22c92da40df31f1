/* SPDX-License-Identifier: ISC */
/* psensd: the photosensor commissioning daemon.  It loads the scene's
 * precomputed ratios (rerunning psscene when they are stale), reads the
 * photosensors, commands the ballasts, logs every sample, and takes commands
 * on its control socket.  With -s it runs the [simulate] day on a simulated
 * clock, through the same event loop, and prints a summary.
 * See psensd(8) and psensd.conf(5). */
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "loop.h"
#include "annual.h"
#include "canvas.h"
#include "accept.h"
#include "dated.h"
#include "log.h"
#include "registry.h"
#include "time.h"
#include "weather.h"

static void summary(struct psd_daemon *d, double start, double end)
{
	const struct psd_engine *e = &d->engine;
	const struct psd_config *cf = e->cf;
	char t0[24], t1[24], span[32];
	psd_engine_stamp(e, start, t0, sizeof t0);
	psd_engine_stamp(e, end, t1, sizeof t1);
	psd_clock_duration(end - start, span, sizeof span);
	for (size_t i = 0; i < e->nzone; i++) {
		const struct psd_zone *z = &e->zone[i];
		const struct psd_zone_stats *s = &z->st;
		double hours = (end - (s->since > start ? s->since : start)) / 3600.0, used;
		struct ps_truth t;
		if ((s->samples == 0 && s->cal_steps == 0 && s->vacant_steps == 0) || psd_engine_truth(z, end, &t) != 0)
			continue;
		/* numerator and denominator over the same span, across reloads */
		used = psd_engine_zone_energy(s, t.energy) / 3600.0;
		printf("psensd: %s %s to %s (%s; the room's day %s) on the %s room (%s), zone %s every %g s, "
		       "%s control, target %g lx\n", d->clock.simulated ? "simulated" : "ran", t0, t1, span, cf->date,
		       z->sim->drv->name, z->res ? z->res->scene : "-", z->zc->name, z->zc->period,
		       psd_control_algorithm_names[z->ctl.algorithm], z->ctl.target_lux);
		if (z->res)
			printf("  simulated ratios: daylight %.2f, electric %.2f lx per unit (task-sensor ratio %.3f)\n",
			       z->res->daylight_ratio_mean, z->res->electric_ratio, z->res->task_sensor_ratio);
		if (hours >= 1)
			printf("  energy: %.1f %% of full output (%.2f of %.2f full-output hours)\n", 100 * used / hours,
			       used, hours);
		else if (hours > 0)
			printf("  energy: %.1f %% of full output (%.2f of %.2f full-output minutes)\n",
			       100 * used / hours, 60 * used, 60 * hours);
		if (s->cal_steps > 0) {
			printf("  calibration sessions held the lights for %.0f periods (with the %g s after each), "
			       "not counted below:", s->cal_steps, PSD_ACCEPT_SETTLE_S);
			for (int k = 0; k < s->ncal; k++) {
				char a[24], b[24];
				psd_engine_stamp(e, s->cal_from[k], a, sizeof a);
				psd_engine_stamp(e, s->cal_to[k], b, sizeof b);
				printf("%s %s to %s", k ? "," : "", a, b);
			}
			printf("\n");
		}
		if (z->occupancy >= 0) {
			struct psd_occupancy occ = z->occ, *o = &occ;
			psd_occupancy_account(o, end, NAN, NAN);   /* to the end of the run */
			printf("  occupancy: occupied %.2f h, vacant %.2f h (%.2f h at the vacant level %.0f %%, after %.0f s); "
			       "the vacancy saved %.2f full-output hours\n", o->occupied_s / 3600, o->vacant_s / 3600,
			       o->held_s / 3600, 100 * o->vacant_level, o->hold, o->saved / 3600);
		}
		if (s->samples > 0)
			printf("  time below target (by more than %.0f %%): %.1f %% (%.0f of %.0f %speriods; lowest %.0f lx)\n",
			       100 * cf->tolerance, 100 * s->below / s->samples, s->below, s->samples,
			       z->occupancy >= 0 ? "occupied " : "", s->worst_lux);
		if (s->err_n > 0)
			printf("  estimated against true task illuminance: mean %+.2f %%, rms %.2f %%, worst %.2f %%\n",
			       100 * s->err_sum / s->err_n, 100 * sqrt(s->err2_sum / s->err_n), 100 * s->err_max);
		printf("  periods at the safe level after a fault: %.0f\n", s->fault_steps);
		if (e->lat_n)
			printf("  reading to command: mean %.1f us, worst %.1f us; %lu samples logged\n",
			       1e6 * e->lat_sum / (double)e->lat_n, 1e6 * e->lat_max, e->logged);
	}
	fflush(stdout);
}

/* The local midnight of the [simulate] date in its year (or this year). */
static double config_date(const struct psd_config *cf)
{
	int m, day;
	double epoch;
	long year = cf->run_year;
	if (year == 0) {
		struct tm tm;
		if (psd_time_local(psd_time_wall(), &tm) != 0)
			return NAN;
		year = tm.tm_year + 1900;
	}
	if (sscanf(cf->date, "%d-%d", &m, &day) != 2 || psd_clock_midnight((int)year, m, day, &epoch) != 0)
		return NAN;
	return epoch;
}

/* -Y: the whole year of the results for every zone, its figures, the
 * algorithms side by side, and the year drawn (annual.h). */
/* The year picture's name for its weather: the file and the place its
 * header names, said to be synthetic when it is (pssynwea names every
 * place it writes "..._synthetic"). */
static void weather_title(const char *path, char *out, size_t n)
{
	const char *base = strrchr(path, '/');
	struct ps_weather w = { 0 };
	struct ps_err e;
	base = base ? base + 1 : path;
	if (ps_weather_read(&w, path, 0, &e) != 0) {
		snprintf(out, n, "%s", base);
		return;
	}
	snprintf(out, n, "%s: %s%s", base, w.site.name,
	         strstr(w.site.name, "synthetic") ? ", a synthetic year, not measured weather" : "");
	ps_weather_free(&w);
}

/* An effectiveness above 100 % is the law saving by leaving the task short
 * of its target (annual.h): say so next to it, with the hours, the lux they
 * are short by and the effectiveness with lighting delivered at target. */
static void print_above_ideal(const struct psd_annual *a, double target)
{
	if (!(a->effectiveness > 1))
		return;
	if (!(a->short_h > 0)) {
		printf("    above 100 %%: the law uses less power than the ideal photocell with the task\n"
		       "    within 0.1 %% of its target or above (dimmed below the ideal's floor, or off)\n");
		return;
	}
	printf("    above 100 %% by under-lighting: %.1f occupied hours with the task short of the\n"
	       "    %g lx target, by %.0f lx on average, saving %.2f full-power hours there; with\n"
	       "    those hours charged the ideal's power (lighting delivered at target): %.1f %%\n",
	       a->short_h, target, a->short_lxh / a->short_h, a->short_saved_h,
	       100 * a->effectiveness_at_target);
}

/* A sub-hourly year measures what an hourly file's interpolation would
 * cost this scene (annual.h, psd_annual_inhour). */
static void print_inhour(const struct ps_results *r, const struct psd_control *ctl,
                         const struct psd_annual_opt *o, const struct psd_annual *a, double step)
{
	struct psd_annual_inhour b;
	int rc = psd_annual_inhour(r, ctl, o, &b);
	printf("  daylight inside each step: linear between the weather's steps of %.0f min\n", step / 60);
	if (rc == -1) {
		printf("    (no step at the hours' middles: no in-hour error measured)\n");
		return;
	}
	if (rc != 0) {
		printf("    (the in-hour error could not be measured: %s)\n",
		       rc == -2 ? "out of memory" : "the hourly year's steps are not the year's");
		return;
	}
	char rms[48] = "no step with 50 lx or more";
	if (b.task_n > 0)
		snprintf(rms, sizeof rms, "rms %.1f %% a step with 50 lx or more", 100 * b.task_rms);
	printf("    measured for this scene, the year on its %.0f steps at the hours' middles alone\n"
	       "    (as an hourly file, linear between the hours) against the year at its own steps:\n"
	       "    task daylight %+.2f %% over the occupied hours (%s), energy %+.1f %%,\n"
	       "    over-dimmed hours %.1f against %.1f\n",
	       b.hours, 100 * b.task_sum, rms,
	       a->energy_h > 0 ? 100 * (b.hourly.energy_h / a->energy_h - 1) : 0.0, b.hourly.overdim_h,
	       a->overdim_h);
}

static int year_report(struct psd_daemon *d, const char *png)
{
	static const char *const mon[] = { "Jan", "Feb", "Mar", "Apr", "May", "Jun",
	                                   "Jul", "Aug", "Sep", "Oct", "Nov", "Dec" };
	static float task[PSD_ANNUAL_MAX_DAYS * 144], level[PSD_ANNUAL_MAX_DAYS * 144];
	const struct psd_engine *e = &d->engine;
	if (!e->have_res || !e->res.have_year) {
		psd_log_errx("-Y needs results with a year: give the scene a weather file "
		         "(psscene(5), [daylight_coefficients] weather =)");
		return 1;
	}
	for (size_t i = 0; i < e->nzone; i++) {
		const struct psd_zone *z = &e->zone[i];
		struct psd_annual_opt o = { .period = z->zc->period, .occ_start = e->cf->occ_from,
		                            .occ_end = e->cf->occ_to, .dated = 1, .task_img = task, .level_img = level };
		char from[8], to[8], devices[256], err[512];
		struct psd_annual a, b;
		struct psd_control ctl = z->ctl;
		if (psd_annual_devices(e->cf, z->zc, &o, devices, sizeof devices, err, sizeof err) != 0) {
			psd_log_errx("zone %s: %s", z->zc->name, err);
			return 1;
		}
		if (psd_annual_run(&e->res, &ctl, &o, &a) != 0) {
			psd_log_errx("zone %s: the year cannot run (no electric condition?)", z->zc->name);
			return 1;
		}
		psd_clock_hhmm(o.occ_start, from);
		psd_clock_hhmm(o.occ_end, to);
		if (!(a.occ_h > 0)) {
			/* every figure is a share of the occupied hours: none to give */
			psd_log_errx("zone %s: no control step of the year falls in the occupied hours "
			             "%s-%s (a step every %g s): no energy or savings to give; use a period "
			             "that steps inside them", z->zc->name, from, to, o.period);
			return 1;
		}
		printf("psensd: the year of %s, zone %s, %s control (dated estimate) every %g s, "
		       "target %g lx\n",
		       e->res.weather, z->zc->name, psd_control_algorithm_names[ctl.algorithm], o.period,
		       ctl.target_lux);
		printf("  %.0f control steps in %.2f s (%.0f ns a step); occupied %s-%s every day, "
		       "%.0f h\n", a.steps, a.seconds, 1e9 * a.seconds / a.steps, from, to, a.occ_h);
		if (a.days != 365)
			printf("  %d days: the weather file's year has February 29\n", a.days);
		printf("  devices: %s\n", devices);
		printf("  light output %.2f full-output hours (%.1f %% of full)\n", a.light_h, 100 * a.light_h / a.occ_h);
		printf("  lighting energy %.2f full-power hours (%.1f %% of full), savings %.1f %%", a.energy_h,
		       100 * a.energy_h / a.occ_h, 100 * a.savings);
		if (o.watts > 0)
			printf("; %.1f kWh at %g W", a.kwh, o.watts);
		printf("\n");
		{
			/* the day psensd -s plays, from the year's run */
			int m = 0, md = 0, doy = psd_dated_day(e->cf->date);
			if (sscanf(e->cf->date, "%d-%d", &m, &md) == 2 && m > 2 && a.days == 366)
				doy++;
			if (doy >= 1 && doy <= a.days)
				printf("  the [simulate] date %s (what psensd -s plays with year = yes): light output %.4f "
				       "full-output hours over the occupied hours\n", e->cf->date, a.day_light_h[doy - 1]);
		}
		{
			/* an hourly file cannot measure its own in-hour error: the
			 * one figure there is, the example office's, is given as
			 * that office's, with its source, never as this site's */
			double step = psd_annual_weather_step(&e->res);
			if (step >= 3599)
				printf("  daylight inside each hour: linear between the weather's hours; its error is not\n"
				       "    measured for this site (that needs sub-hourly weather). For comparison only,\n"
				       "    the example office's measured figure (doc/year.md; not this site's): against\n"
				       "    San Francisco Intl's TMY3 hours at 10-minute steps (NREL's typical year,\n"
				       "    ladybug-tools' san_francisco_10min.wea), task daylight -0.75 %% over the\n"
				       "    occupied hours (rms 8.1 %% a step), energy -0.8 %%, over-dimmed hours 16.9\n"
				       "    against 3.7\n");
			else if (step > 0)
				print_inhour(&e->res, &ctl, &o, &a, step);
		}
		{
			/* the sun's discretisation error, estimated on this scene's own
			 * coefficients (annual.h, psd_annual_sunbar) */
			struct psd_annual_sunbar sb;
			if (psd_annual_sunbar(&e->res, &ctl, &o, &sb) == 0 && sb.hours > 0)
				printf("  the sun's placement (its light shared among the four nearest patches, MF %d),\n"
				       "    an estimate of its error from this scene's coefficients: the year again with\n"
				       "    the sun in its nearest patch moves occupied hours' task daylight by up to %.0f %%\n"
				       "    (95th percentile %.1f %%, median %.1f %%; %.0f hours with 50 lx or more), their sum\n"
				       "    by %+.2f %%; energy %.2f full-power hours (%+.2f h), savings %.1f %% (%+.3f points),\n"
				       "    below 90 %% %.1f h (%+.1f h); %.2f s\n",
				       e->res.year_mf, 100 * sb.task_max, 100 * sb.task_p95, 100 * sb.task_median, sb.hours,
				       100 * sb.task_sum, sb.alt.energy_h, sb.alt.energy_h - a.energy_h,
				       100 * sb.alt.savings, 100 * (sb.alt.savings - a.savings), sb.alt.below_h,
				       sb.alt.below_h - a.below_h, sb.seconds);
			else if (!e->res.year.have_alt && e->res.year.patches > 0)
				printf("  the sun's placement: no estimate of its error (results without the sun in its\n"
				       "    nearest patch: a 5-phase sun, or written by an older psscene)\n");
		}
		if (isfinite(a.effectiveness)) {
			printf("  ideal photocell (DAYSIM: output from the task's true daylight) saves %.1f %%: "
			       "effectiveness %.1f %%\n", 100 * a.ideal_savings, 100 * a.effectiveness);
			print_above_ideal(&a, ctl.target_lux);
		} else   /* nothing to save: no effectiveness to give */
			printf("  ideal photocell (DAYSIM: output from the task's true daylight) saves %.1f %%: "
			       "no effectiveness to give\n", 100 * a.ideal_savings);
		printf("  occupied hours below 90 %% of target: %.1f h (%.2f %%); over-dimmed %.1f h; "
		       "%.2f dimming changes an hour\n", a.below_h, 100 * a.below_h / a.occ_h,
		       a.overdim_h, a.changes_per_h);
		if (!(a.est_n > 0))
			printf("  daylight estimate against the task's true daylight: no step with 50 lx or more\n");
		else
			printf("  daylight estimate against the task's true daylight (%.0f steps with 50 lx or more):\n"
			       "    one mean ratio (%.1f): mean %+.1f %%, rms %.1f %%\n"
			       "    dated ratio (month x hour x typical sky class): mean %+.1f %%, rms %.1f %%\n",
			       a.est_n, e->res.year.mean_ratio, a.est_mean[0], a.est_rms[0], a.est_mean[1],
			       a.est_rms[1]);
		if (a.est_rooftop && a.est_n > 0)
			printf("    dated ratio, sky class from a rooftop sensor: mean %+.1f %%, rms %.1f %%\n",
			       a.est_mean[2], a.est_rms[2]);
		printf("  %-5s %9s %9s %9s %9s %9s\n", "month", "occ. h", "energy %", "ideal %",
		       "below 90%", "overdim h");
		for (int m = 0; m < 12; m++) {
			const struct psd_annual_month *k = &a.month[m];
			if (!(k->occ_h > 0)) {   /* no occupied step this month: no shares */
				printf("  %-5s %9.0f %9s %9s %9.1f %9.1f\n", mon[m], k->occ_h, "-", "-", k->below_h,
				       k->overdim_h);
				continue;
			}
			printf("  %-5s %9.0f %9.1f %9.1f %9.1f %9.1f\n", mon[m], k->occ_h,
			       100 * k->energy_h / k->occ_h, 100 * k->ideal_h / k->occ_h, k->below_h,
			       k->overdim_h);
		}
		if (png && i == 0) {
			char title[512], wx[320];
			int rc;
			const char *sb = e->res.scene ? strrchr(e->res.scene, '/') : NULL;
			weather_title(e->res.weather, wx, sizeof wx);
			snprintf(title, sizeof title, "%s: zone %s, %s, target %g lx (%s)",
			         sb ? sb + 1 : e->res.scene ? e->res.scene : "", z->zc->name,
			         psd_control_algorithm_names[ctl.algorithm], ctl.target_lux, wx);
			rc = psd_annual_png(png, task, level, a.days, ctl.target_lux, title, err, sizeof err);
			ps_canvas_shutdown();   /* the fonts' caches: nothing left for leak checkers */
			if (rc != 0) {
				psd_log_errx("%s", err);
				return 1;
			}
			printf("  the year drawn: %s\n", png);
		}
		/* the laws side by side, each with the zone's constants */
		printf("  the control laws over the year (the zone's constants; switching thresholds\n"
		       "  from the model where the zone sets none):\n");
		printf("  %-32s %9s %9s %9s %9s %9s %9s %9s\n", "algorithm (dated ratio)", "energy %",
		       "savings %", "effect. %", "at tgt %", "below90 h", "overdim h", "changes/h");
		for (int row = 0; row < PSD_ALG_COUNT + 2; row++) {
			/* the five laws with the dated ratio, then the two that use a
			 * ratio again with the one mean ratio */
			int alg = row < PSD_ALG_COUNT ? row
			          : row == PSD_ALG_COUNT ? PSD_ALG_SETPOINT : PSD_ALG_CLOSED_PROPORTIONAL;
			struct psd_control c = z->ctl;
			struct psd_annual_opt q = o;
			char name[48];
			c.algorithm = alg;
			q.task_img = q.level_img = NULL;
			q.dated = row < PSD_ALG_COUNT;
			if (alg == PSD_ALG_SWITCHING && c.s_off >= 1e9) {
				double full = c.sensor_gain * c.elec_sensor;
				double need = c.sensor_gain * c.target_lux / e->res.year.mean_ratio;
				c.s_on = need;
				c.s_off = full + need;
			}
			if (psd_annual_run(&e->res, &c, &q, &b) != 0)
				continue;
			snprintf(name, sizeof name, "%s%s", psd_control_algorithm_names[alg],
			         row < PSD_ALG_COUNT ? "" : ", mean ratio");
			{
				char eff[16] = "-", eff_t[16] = "-";
				if (isfinite(b.effectiveness))
					snprintf(eff, sizeof eff, "%.1f", 100 * b.effectiveness);
				if (isfinite(b.effectiveness_at_target))
					snprintf(eff_t, sizeof eff_t, "%.1f", 100 * b.effectiveness_at_target);
				printf("  %-32s %9.1f %9.1f %9s %9s %9.1f %9.1f %9.2f\n", name,
				       100 * b.energy_h / b.occ_h, 100 * b.savings, eff, eff_t, b.below_h,
				       b.overdim_h, b.changes_per_h);
			}
		}
	}
	fflush(stdout);
	return 0;
}

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psensd [-f config] [-n | -s | -Y [-P png]] [-t HH:MM] [-d YYYY-MM-DD] [-x speed] [-v] | -L\n"
	            "  -f FILE   configuration (default /etc/psensd/psensd.conf)\n"
	            "  -n        check the configuration and exit\n"
	            "  -s        run the [simulate] day on a simulated clock and print a summary\n"
	            "  -Y        run the results' whole year for every zone and print its figures\n"
	            "  -P FILE   with -Y: draw the year (first zone) as a PNG\n"
	            "  -t HH:MM  real time: start the clock at this time of day (default: now)\n"
	            "  -x SPEED  real time: run the clock SPEED times faster (tests, demonstrations)\n"
	            "  -d DATE   the date of a run with -s or -t (default: [simulate] date and run_year)\n"
	            "  -v        more messages\n"
	            "  -h, --help  this help;  -V, --version  the version\n"
	            "  -L, --list-driver-options  every driver's keys, defaults and ranges\n");
#ifdef PS_WITH_MQTT
	fprintf(fp, "mqtt: [mqtt], psensd-mqtt(7)\n");
#else
	fprintf(fp, "mqtt: [mqtt], psensd-mqtt(7) (not compiled in)\n");
#endif
#ifndef PS_WITH_QRENCODE
	fprintf(fp, "qrencode: not compiled in (the record has no QR codes to the console)\n");
#endif
#ifdef PS_WITH_WEB
	fprintf(fp, "web: [web], the on-site console (psensd.conf(5))\n");
#else
	fprintf(fp, "web: [web], the on-site console (psensd.conf(5)) (not compiled in)\n");
#endif
	fprintf(fp, "drivers:\n");
	for (int i = 0; ps_registry_drivers[i]; i++)
		fprintf(fp, "  %-9s %s%s\n", ps_registry_drivers[i]->name, ps_registry_drivers[i]->summary,
		        ps_registry_drivers[i]->compiled_in ? "" : " (not compiled in)");
}

/* What a key takes, for -L: its range, its choices, or its kind. */
static void accepts(const struct ps_opts_spec *o, char *out, size_t n)
{
	size_t len = 0;
	out[0] = 0;
	if (o->names) {
		for (int i = 0; o->names[i] && len < n; i++)
			len += (size_t)snprintf(out + len, n - len, "%s%s", i ? "|" : "", o->names[i]);
		if (o->type == PS_OPT_WINDOWS)
			snprintf(out + len, n - len, " HH:MM-HH:MM,...");
	} else if (o->type == PS_OPT_DOUBLE) {
		snprintf(out, n, "%g..%g", o->min, o->max);
	} else if (o->type == PS_OPT_LONG) {
		snprintf(out, n, "%.0f..%.0f", o->min, o->max);
	} else if (o->type == PS_OPT_BOOL) {
		snprintf(out, n, "yes|no");
	} else if (o->type == PS_OPT_WINDOWS) {
		snprintf(out, n, "HH:MM-HH:MM,...");
	} else {
		snprintf(out, n, "text");
	}
}

/* -L: every driver's option table, one key a line. */
static void list_options(void)
{
	for (int i = 0; ps_registry_drivers[i]; i++) {
		const struct ps_driver *drv = ps_registry_drivers[i];
		printf("%s%s: %s\n", drv->name, drv->compiled_in ? "" : " (not compiled in)", drv->summary);
		for (const struct ps_opts_spec *o = drv->options; o && o->key; o++) {
			char what[200], roles[64] = "";
			size_t len = 0;
			accepts(o, what, sizeof what);
			for (int r = 0; r < PS_ROLE_COUNT && o->roles; r++)
				if (o->roles & PS_ROLE_BIT(r))
					len += (size_t)snprintf(roles + len, sizeof roles - len, "%s%s", len ? "," : " (",
					                        ps_role_name(r));
			printf("  %-6s %-13s %-7s default %-10s %s%s%s: %s\n", o->scope == PS_OPT_DEVICE ? "device" : "point",
			       o->key, ps_opts_type_names[o->type], o->def ? o->def : "-", what, roles, len ? ")" : "",
			       o->doc);
		}
	}
}

/* The end of the run, before the summary (it commits the log): a fault
 * drives every zone to its safe level; a planned stop (SIGTERM, SIGINT,
 * the simulated run's end) to its stop level (psensd(8), STOPPING).  The
 * count of zones that could not be commanded. */
static int loop_end(struct psd_daemon *d)
{
	if (d->fault) {
		psd_log_errx("%s: the lights to the safe level", d->fault);
		return psd_loop_end(d, d->fault, 0);
	}
	if (d->stop) {
		psd_log_info("%s: stopping", strsignal(d->stop));
		return psd_loop_end(d, strsignal(d->stop), 1);
	}
	return psd_loop_end(d, "end of the simulated day", 1);
}

int main(int argc, char **argv)
{
	const char *path = "/etc/psensd/psensd.conf";
	int check = 0, simulate = 0, verbose = PSD_LOG_INFO, opt, rc = 0, unsafe;
	double start = NAN, speed = 1, epoch0 = NAN;
	const char *date = NULL;
	static struct psd_daemon d;
	static struct psd_config cf;
	char *end;
	static const struct option longopts[] = {
		{ "list-driver-options", no_argument, NULL, 'L' },
		PS_CLI_LONGOPTS,
		{ NULL, 0, NULL, 0 },
	};
	const char *png = NULL;
	int year = 0, have_t = 0, have_x = 0;
	while ((opt = getopt_long(argc, argv, "f:nst:x:d:vhVLYP:", longopts, NULL)) != -1) {
		switch (opt) {
		case 'L': list_options(); return 0;
		case 'f': path = optarg; break;
		case 'n': check = 1; break;
		case 's': simulate = 1; break;
		case 'Y': year = simulate = 1; break;
		case 'P': png = optarg; break;
		case 't':
			if (psd_time_hhmm(optarg, &start) != 0) {
				fprintf(stderr, "psensd: -t %s: not HH:MM\n", optarg);
				return 2;
			}
			have_t = 1;
			break;
		case 'x':
			speed = strtod(optarg, &end);
			if (*end || !(speed >= 0.001 && speed <= 1e6)) {
				fprintf(stderr, "psensd: -x %s: a speed from 0.001 to 1e6\n", optarg);
				return 2;
			}
			have_x = 1;
			break;
		case 'd':
			if (psd_clock_parse_date(optarg, &epoch0) != 0) {
				fprintf(stderr, "psensd: -d %s: not a date YYYY-MM-DD\n", optarg);
				return 2;
			}
			date = optarg;
			break;
		case 'v': verbose = PSD_LOG_DEBUG; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psensd");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc) {
		usage(stderr);
		return 2;
	}
	/* no option is silently ignored: -t and -x set the real-time clock,
	 * which neither -s (the [simulate] day) nor -n (no clock) has */
	if ((simulate || check) && (have_t || have_x)) {
		fprintf(stderr, "psensd: %s%s%s %s the real-time clock, which %s does not run%s\n",
		        have_t ? "-t" : "", have_t && have_x ? " and " : "", have_x ? "-x" : "",
		        have_t && have_x ? "set" : "sets", year ? "-Y" : simulate ? "-s" : "-n",
		        year ? " (it runs the results' year)" : simulate ? " (its [simulate] section sets the day)" : "");
		return 2;
	}
	if (simulate && check) {
		fprintf(stderr, "psensd: -n and %s: one or the other\n", year ? "-Y" : "-s");
		return 2;
	}
	if (png && !year) {
		fprintf(stderr, "psensd: -P draws the year: it goes with -Y\n");
		return 2;
	}
	psd_log_init(1, verbose, "psensd");
	if (check) {
		rc = psd_config_load_judged(&cf, path);
		psd_loop_config_errors(&cf);
#ifndef PS_WITH_MQTT
		if (rc == 0 && cf.mqtt.enabled) {   /* it would be refused at start */
			psd_log_errx("%s:%d: [mqtt]: this psensd was built without MQTT (WITH_MQTT=no or no libmosquitto)",
			         path, cf.mqtt.line);
			rc = -1;
		}
#endif
#ifndef PS_WITH_WEB
		if (rc == 0 && cf.web.enabled) {   /* it would be refused at start */
			psd_log_errx("%s:%d: [web]: this psensd was built without the web console (WITH_WEB=no or no "
			             "libmicrohttpd)", path, cf.web.line);
			rc = -1;
		}
#endif
		if (rc == 0)
			printf("%s: configuration OK (%zu device(s), %zu point(s), %zu zone(s))\n", path, cf.ndev,
			       cf.npt, cf.nzone);
		psd_config_free(&cf);
		return rc == 0 ? 0 : 1;
	}
	/* the site's time zone: every local date and time is the site's */
	if (psd_config_load(&cf, path) == 0 && cf.timezone) {
		setenv("TZ", cf.timezone, 1);
		tzset();
	}
	psd_config_free(&cf);
	memset(&cf, 0, sizeof cf);
	/* the clock's origin: the [simulate] start, -t, or now */
	if (simulate) {
		if (psd_config_load(&cf, path) != 0) {
			psd_loop_config_errors(&cf);
			psd_config_free(&cf);
			return 1;
		}
		psd_clock_simulated(&d.clock, cf.start);
		d.end = cf.end;
		if (!date)
			epoch0 = config_date(&cf);
		psd_config_free(&cf);
	} else {
		psd_clock_real(&d.clock, isnan(start) ? psd_clock_local_tod() : start, speed);
		d.end = INFINITY;
		if (!isnan(start) && !date) {
			/* a set clock: the configuration's date (its errors come at start) */
			if (psd_config_load(&cf, path) == 0)
				epoch0 = config_date(&cf);
			psd_config_free(&cf);
			memset(&cf, 0, sizeof cf);
		} else if (isnan(start)) {
			/* the wall clock: today, and its steps from now on */
			psd_wallstep_init(&d.wall, PSD_WALL_STEP_MS / 1000.0);
			epoch0 = psd_wallstep_wall() - psd_clock_now(&d.clock);
			d.wall_dated = 1;
			if (date)
				psd_log_warnx("-d %s: ignored without -s or -t: the run is dated by the wall clock", date);
		}
	}
	d.clock.epoch0 = epoch0;
	/* a date taken from the configuration moves on past days on record */
	d.advance_date = (simulate || !isnan(start)) && !date;
	d.self = argv[0];
	d.dry = year;
	start = psd_clock_now(&d.clock);
	if (psd_loop_start(&d, path) != 0) {
		psd_loop_stop(&d, NULL);   /* what it did open (the signalfd) */
		return 1;
	}
	if (!simulate && !d.engine.cf->sim_year)
		d.engine.month = psd_dated_month(NULL);   /* the dated estimate: today's month */
	if (year) {
		rc = year_report(&d, png);
		psd_loop_stop(&d, NULL);
		return rc;
	}
	psd_log_info("controlling %zu zone(s) from %s on a %s clock", d.engine.nzone, path,
	         simulate ? "simulated" : "real-time");
	psd_loop_run(&d);
	unsafe = loop_end(&d);
	summary(&d, start, psd_clock_now(&d.clock));
	psd_loop_stop(&d, NULL);
	/* a shutdown that leaves lights where nobody can see them, or a run
	 * ended by a fault, is a failure: said at LOG_ERR, and the exit status
	 * says it to systemd and scripts */
	if (unsafe) {
		psd_log_errx("stopped with %d zone(s) not at their %s level: check the outputs", unsafe,
		             d.fault ? "safe" : "stop");
		rc = 1;
	}
	if (d.fault) {
		psd_log_errx("stopped by a fault: %s", d.fault);
		rc = 1;
	}
	return rc;
}
