/* psensd: the photosensor commissioning daemon.
 *
 * This first version runs the control over a simulated day on the loopback
 * room built from the scene's precomputed ratios (-s), and checks a
 * configuration (-n).  Real-time operation with the event loop, the SQLite
 * log and the control socket is the daemon issue's remaining work.
 * See psensd(8) and psensd.conf(5). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "conf.h"
#include "control.h"
#include "db.h"
#include "driver.h"
#include "log.h"
#include "loopback.h"
#include "results.h"
#include "room.h"
#include "roomsetup.h"

extern char **environ;

#define MAX_OPTS 64

struct config {
	struct ps_conf conf;
	char *results, *scene, *database;
	double period, safe_level, sensor_min, sensor_max, tolerance;
	char date[16];
	double start, end, sunrise, sunset;
	/* the one zone and its device */
	char *device_name;
	const struct ps_driver *drv;
	struct ps_opt opts[MAX_OPTS];
	struct ps_opts dev_opts;
	struct psd_control ctl;
};

static int hhmm(struct ps_conf *c, struct ps_conf_section *s, const char *key, double def, double *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	int h, m, n = 0;
	*out = def;
	if (!kv)
		return 0;
	if (sscanf(kv->value, "%d:%d%n", &h, &m, &n) != 2 || kv->value[n] || h < 0 || h > 24 || m < 0 || m > 59) {
		ps_conf_error(c, kv->line, "%s: '%s' is not HH:MM", key, kv->value);
		return -1;
	}
	*out = h * 3600.0 + m * 60.0;
	return 0;
}

/* Read and check the whole configuration; every error is printed, all in one pass. */
static int config_load(struct config *cf, const char *path)
{
	struct ps_err e;
	struct ps_conf *c = &cf->conf;
	struct ps_conf_section *s, *zone = NULL, *dev = NULL;
	const char *v;
	memset(cf, 0, sizeof *cf);
	if (ps_conf_load(c, path, &e) != 0) {
		log_warnx("%s", e.msg);
		return -1;
	}
	s = ps_conf_section(c, "psensd");
	cf->results = ps_conf_path(c, s, "results");
	cf->scene = ps_conf_path(c, s, "scene");
	cf->database = ps_conf_path(c, s, "database");
	if (!cf->results)
		ps_conf_error(c, s ? s->line : 0, "[psensd] needs 'results' (a psscene results file)");
	ps_conf_double(c, s, "period", 60, 0.001, 86400, &cf->period);
	ps_conf_double(c, s, "safe_level", 1.0, 0, 1, &cf->safe_level);
	ps_conf_double(c, s, "sensor_min", 0.01, -100, 100, &cf->sensor_min);
	ps_conf_double(c, s, "sensor_max", 9.9, -100, 1000, &cf->sensor_max);
	s = ps_conf_section(c, "simulate");
	snprintf(cf->date, sizeof cf->date, "%s", ps_conf_str(c, s, "date", "03-18"));
	if (psd_day_of_year(cf->date) < 0)
		ps_conf_error(c, ps_conf_kv(s, "date") ? ps_conf_kv(s, "date")->line : 0,
		              "date: '%s' is not MM-DD", cf->date);
	hhmm(c, s, "start", 6 * 3600.0, &cf->start);
	hhmm(c, s, "end", 20 * 3600.0, &cf->end);
	hhmm(c, s, "sunrise", 6 * 3600.0, &cf->sunrise);
	hhmm(c, s, "sunset", 18 * 3600.0, &cf->sunset);
	ps_conf_double(c, s, "tolerance", 0.02, 0, 1, &cf->tolerance);
	for (size_t i = 0; i < c->nsec; i++) {
		if (ps_conf_section_is(&c->sec[i], "zone")) {
			if (zone)
				ps_conf_error(c, c->sec[i].line, "this version runs one [zone]");
			zone = &c->sec[i];
			zone->used = 1;
		}
	}
	if (!zone) {
		ps_conf_error(c, 0, "no [zone NAME] section");
	} else {
		struct psd_control *k = &cf->ctl;
		char name[160];
		v = ps_conf_str(c, zone, "device", NULL);
		if (!v)
			ps_conf_error(c, zone->line, "[%s] needs 'device'", zone->name);
		else {
			snprintf(name, sizeof name, "device %s", v);
			dev = ps_conf_section(c, name);
			if (!dev)
				ps_conf_error(c, ps_conf_kv(zone, "device")->line, "device: no [device %s]", v);
			cf->device_name = strdup(v);
		}
		ps_conf_enum(c, zone, "algorithm", psd_algorithm_names, PSD_ALG_SETPOINT, &k->algorithm);
		ps_conf_double(c, zone, "target_lux", 500, 0, 1e6, &k->target_lux);
		ps_conf_double(c, zone, "min_level", 0.1, 0, 1, &k->min_level);
		ps_conf_double(c, zone, "max_step", 0, 0, 1, &k->max_step);
		ps_conf_double(c, zone, "hysteresis", 0, 0, 1, &k->hysteresis);
		ps_conf_double(c, zone, "sensor_gain", 1, 1e-12, 1e12, &k->sensor_gain);
		ps_conf_double(c, zone, "s_full", 0, 0, 1e6, &k->s_full);
		ps_conf_double(c, zone, "s_set", 0, 0, 1e6, &k->s_set);
		ps_conf_double(c, zone, "ki", 1, 0, 100, &k->ki);
		ps_conf_double(c, zone, "s_off", 1e9, 0, 1e9, &k->s_off);
		ps_conf_double(c, zone, "s_on", 0, 0, 1e9, &k->s_on);
		ps_conf_double(c, zone, "delay", 300, 0, 86400, &k->delay);
		{
			long steps;
			ps_conf_int(c, zone, "steps", 1, 1, 16, &steps);
			k->steps = (int)steps;
		}
		if (k->s_on > k->s_off)
			ps_conf_error(c, zone->line, "[%s]: s_on must not exceed s_off (the deadband)", zone->name);
	}
	if (dev) {
		v = ps_conf_str(c, dev, "driver", NULL);
		if (!v)
			ps_conf_error(c, dev->line, "[%s] needs 'driver'", dev->name);
		else if (!(cf->drv = ps_driver_find(v)))
			ps_conf_error(c, ps_conf_kv(dev, "driver")->line, "driver: no driver '%s'", v);
		/* the rest of the section is the driver's: it reports what it does not know */
		for (size_t j = 0; j < dev->nkv && cf->dev_opts.n < MAX_OPTS; j++) {
			if (strcmp(dev->kv[j].key, "driver") == 0)
				continue;
			dev->kv[j].used = 1;
			cf->opts[cf->dev_opts.n++] = (struct ps_opt){ dev->kv[j].key, dev->kv[j].value,
			                                              dev->kv[j].line, 0 };
		}
		cf->dev_opts.v = cf->opts;
		cf->dev_opts.file = c->path;
	}
	ps_conf_check_unused(c);
	for (size_t i = 0; i < c->nerrors; i++)
		log_warnx("%s", c->errors[i]);
	return c->nerrors ? -1 : 0;
}

static void config_free(struct config *cf)
{
	free(cf->results);
	free(cf->scene);
	free(cf->database);
	free(cf->device_name);
	ps_conf_free(&cf->conf);
}

/* Recompute the results with psscene when they are missing or older than
 * the scene file. */
static int refresh_results(const struct config *cf, const char *self)
{
	struct stat rs, ss;
	char psscene[4096];
	const char *slash = strrchr(self, '/');
	char *argv[6];
	pid_t pid;
	int status;
	if (!cf->scene)
		return 0;
	if (stat(cf->scene, &ss) != 0) {
		log_warn("%s", cf->scene);
		return -1;
	}
	if (stat(cf->results, &rs) == 0 && rs.st_mtime >= ss.st_mtime)
		return 0;
	/* psscene beside this psensd, else on PATH */
	if (slash)
		snprintf(psscene, sizeof psscene, "%.*s/psscene", (int)(slash - self), self);
	if (!slash || access(psscene, X_OK) != 0)
		snprintf(psscene, sizeof psscene, "psscene");
	log_info("results %s missing or older than %s: running %s", cf->results, cf->scene, psscene);
	argv[0] = psscene;
	argv[1] = "-q";
	argv[2] = "-o";
	argv[3] = cf->results;
	argv[4] = cf->scene;
	argv[5] = NULL;
	if ((errno = posix_spawnp(&pid, psscene, NULL, NULL, argv, environ)) != 0) {
		log_warn("cannot run %s", psscene);
		return -1;
	}
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return -1;
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		log_warnx("%s failed on %s", psscene, cf->scene);
		return -1;
	}
	return 0;
}

struct summary {
	double samples, below, fault_samples, worst_lux;
	double err_sum, err2_sum, err_max, err_n;
};

static int simulate_day(struct config *cf)
{
	struct ps_results res;
	struct ps_err e;
	struct ps_room_daypoint day[PSD_DAY_POINTS];
	struct ps_room_params rp;
	struct ps_dev dev;
	struct ps_point sensor = { "sensor", PS_ROLE_SENSOR, NULL }, dim = { "dim", PS_ROLE_DIM, NULL };
	struct ps_room *room;
	struct summary s = { 0, 0, 0, INFINITY, 0, 0, 0, 0 };
	struct psd_db *db = NULL;
	char dberr[512];
	int in_fault = 0;
	double t, e0;
	if (ps_results_read(&res, cf->results, &e) != 0) {
		log_warnx("%s", e.msg);
		return -1;
	}
	if (psd_room_from_results(&res, psd_day_of_year(cf->date), cf->sunrise, cf->sunset, day, &rp) != 0) {
		log_warnx("%s: needs a computed daylight and an electric condition", cf->results);
		ps_results_free(&res);
		return -1;
	}
	if (!cf->drv || strcmp(cf->drv->name, "loopback") != 0) {
		log_warnx("a simulated day needs the loopback room (device driver = loopback)");
		ps_results_free(&res);
		return -1;
	}
	memset(&dev, 0, sizeof dev);
	dev.drv = cf->drv;
	snprintf(dev.name, sizeof dev.name, "%s", cf->device_name);
	if (cf->drv->open(&dev, &cf->dev_opts) != 0 || ps_loopback_set_room(&dev, &rp, cf->start) != 0 ||
	    cf->drv->add_point(&dev, &sensor, NULL) != 0 || cf->drv->add_point(&dev, &dim, NULL) != 0) {
		log_warnx("device %s: %s", dev.name, dev.err);
		cf->drv->close(&dev);
		ps_results_free(&res);
		return -1;
	}
	for (size_t i = 0; i < cf->dev_opts.n; i++)
		if (!cf->dev_opts.v[i].used)
			log_warnx("%s:%d: unknown key '%s' for driver %s", cf->conf.path, cf->dev_opts.v[i].line,
			          cf->dev_opts.v[i].key, cf->drv->name);
	room = ps_loopback_room(&dev);
	if (cf->database && !(db = psd_db_open(cf->database, dberr, sizeof dberr))) {
		log_warnx("%s", dberr);
		cf->drv->close(&dev);
		ps_results_free(&res);
		return -1;
	}
	cf->ctl.daylight_ratio = res.daylight_ratio_mean;
	cf->ctl.elec_sensor = res.electric_sensor_response;
	cf->ctl.elec_task_lux = res.electric_task_lux;
	cf->ctl.level = 1.0;
	cf->drv->write(&dev, &dim, cf->start, 1.0);
	e0 = ps_room_energy(room, cf->start);
	for (t = cf->start; t < cf->end; t += cf->period) {
		double volts = NAN, level, truth;
		int fault = cf->drv->read(&dev, &sensor, t, &volts) != 0;
		if (!fault && (volts < cf->sensor_min || volts > cf->sensor_max)) {
			snprintf(dev.err, sizeof dev.err, "sensor reads %.3f V, outside %g to %g V", volts,
			         cf->sensor_min, cf->sensor_max);
			fault = 1;
		}
		if (fault) {
			if (!in_fault)
				log_warnx("%02d:%02d fault: %s: lights to the safe level %.0f %%", (int)(t / 3600),
				          (int)fmod(t / 60, 60), dev.err, 100 * cf->safe_level);
			in_fault = 1;
			level = cf->safe_level;
			cf->ctl.level = level;
			s.fault_samples++;
		} else {
			if (in_fault)
				log_info("%02d:%02d fault cleared: control resumes", (int)(t / 3600), (int)fmod(t / 60, 60));
			in_fault = 0;
			level = psd_control_step(&cf->ctl, volts, t);
			truth = ps_room_true_task_lux(room, t);
			if (truth > 0) {
				double err = (cf->ctl.est_task_lux - truth) / truth;
				s.err_sum += err;
				s.err2_sum += err * err;
				s.err_n++;
				if (fabs(err) > s.err_max)
					s.err_max = fabs(err);
			}
		}
		cf->drv->write(&dev, &dim, t, level);
		if (db) {
			struct psd_sample smp = {
				t, ps_room_tod(t), volts, level,
				fault ? NAN : cf->ctl.est_task_lux, NAN,
				fault ? NAN : cf->ctl.daylight_volts,
				fault ? NAN : cf->ctl.daylight_ratio * cf->ctl.daylight_volts / cf->ctl.sensor_gain,
				"daylight_mean", cf->ctl.daylight_ratio, fault ? dev.err : NULL
			};
			if (psd_db_add(db, &smp, dberr, sizeof dberr) != 0) {
				/* the log is a record, not the control: say so and go on */
				log_warnx("%s: %s", cf->database, dberr);
			}
		}
		/* the illuminance the occupants get, just before the next reading */
		truth = ps_room_true_task_lux(room, t + cf->period * 0.999);
		if (truth < cf->ctl.target_lux * (1 - cf->tolerance))
			s.below++;
		if (truth < s.worst_lux)
			s.worst_lux = truth;
		s.samples++;
	}
	{
		double hours = (cf->end - cf->start) / 3600.0, used = (ps_room_energy(room, cf->end) - e0) / 3600.0;
		printf("psensd: simulated %s %02d:%02d-%02d:%02d on the loopback room (%s), every %g s, "
		       "%s control, target %g lx\n", cf->date, (int)(cf->start / 3600), (int)fmod(cf->start / 60, 60),
		       (int)(cf->end / 3600), (int)fmod(cf->end / 60, 60), res.scene, cf->period,
		       psd_algorithm_names[cf->ctl.algorithm],
		       cf->ctl.target_lux);
		printf("  simulated ratios: daylight %.2f, electric %.2f lx per unit (task-sensor ratio %.3f)\n",
		       res.daylight_ratio_mean, res.electric_ratio, res.task_sensor_ratio);
		printf("  energy: %.1f %% of full output (%.2f of %.2f full-output hours)\n", 100 * used / hours,
		       used, hours);
		printf("  time below target (by more than %.0f %%): %.1f %% (%.0f of %.0f periods; lowest %.0f lx)\n",
		       100 * cf->tolerance, 100 * s.below / s.samples, s.below, s.samples, s.worst_lux);
		if (s.err_n > 0) {
			double mean = s.err_sum / s.err_n, rms = sqrt(s.err2_sum / s.err_n);
			printf("  estimated against true task illuminance: mean %+.2f %%, rms %.2f %%, worst %.2f %%\n",
			       100 * mean, 100 * rms, 100 * s.err_max);
		}
		printf("  periods at the safe level after a fault: %.0f\n", s.fault_samples);
	}
	psd_db_close(db);
	cf->drv->close(&dev);
	ps_results_free(&res);
	return 0;
}

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psensd [-f config] [-n | -s] [-v]\n"
	            "  -f FILE  configuration (default /etc/psensd/psensd.conf)\n"
	            "  -n       check the configuration and exit\n"
	            "  -s       run the [simulate] day on the loopback room and print a summary\n"
	            "  -v       more messages\n");
}

int main(int argc, char **argv)
{
	const char *path = "/etc/psensd/psensd.conf";
	int check = 0, simulate = 0, verbose = PSD_LOG_INFO, opt, rc;
	struct config cf;
	while ((opt = getopt(argc, argv, "f:nsvh")) != -1) {
		switch (opt) {
		case 'f': path = optarg; break;
		case 'n': check = 1; break;
		case 's': simulate = 1; break;
		case 'v': verbose = PSD_LOG_DEBUG; break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc) {
		usage(stderr);
		return 2;
	}
	log_init(1, verbose, "psensd");
	if (config_load(&cf, path) != 0) {
		config_free(&cf);
		return 1;
	}
	if (check) {
		printf("%s: configuration OK\n", path);
		config_free(&cf);
		return 0;
	}
	if (!simulate) {
		log_warnx("this version runs simulated days only (-s); real-time operation is not built yet");
		config_free(&cf);
		return 2;
	}
	rc = refresh_results(&cf, argv[0]) == 0 && simulate_day(&cf) == 0 ? 0 : 1;
	config_free(&cf);
	return rc;
}
