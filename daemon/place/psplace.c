/* SPDX-License-Identifier: ISC */
/* psplace: where to put which sensor.  Every combination of a candidate
 * pose (its daylight-coefficient pictures and electric picture), a rotation
 * about the sensor's axis, a sensor and a control law is run through the
 * weather year with the zone's real law and device model (annual.h, the
 * engine psensd -Y runs) and scored against a work-plane grid (gridmtx.h);
 * psplace(1) says what each figure means.
 *
 * It lives in daemon/ because it runs the control laws and the device
 * model, which sim/ must not know (the simulation: pictures, projections,
 * the sky, the grid, comes from libpsim), and in a room of its own
 * (daemon/place/, libpsdplace.a) because the daemon never runs it: the
 * core's library stays without it, and the room reaches the core only
 * through the core's headers.  This file is the command line; place.h
 * lists the room's parts.
 *
 * The route: each pose's pictures are projected once per colour channel
 * onto a (theta, phi) grid (rescan.h), and every sensor at every rotation
 * read from the projection (one pass over the cells), not integrated
 * again; the year's sky vectors are made once and shared by every
 * combination.  The best combinations are then integrated exactly
 * (ps_weights_build at their rotation) and run again: the table prints
 * the projection's error on the year's sensor signal and on the energy. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "control.h"
#include "filter.h"
#include "gridmtx.h"
#include "integrate.h"
#include "log.h"
#include "place.h"
#include "placeout.h"
#include "placerender.h"
#include "placerun.h"
#include "placeset.h"
#include "placeyear.h"
#include "time.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psplace -f psensd.conf [-z zone] {-c candidates.txt | --ceiling X0,X1,NX,Y0,Y1,NY,Z\n"
	            "               [--aims A,...]} [-d dir] -g grid.mtx\n"
	            "               -e grid_elec.dat -w weather [-s sensor]... [-a law]... [-r step]\n"
	            "               [-t figure] [-T top] [-n threads] [-p period] [-u hours] [-k deg]\n"
	            "               [-j] [-o out.json] [-x results] [-E schedule.csv] [-y year.csv]\n"
	            "               [-Z zone.conf] [-P plan.png] [-F fisheye.png] [-q]\n"
	            "               [-M room.oct -K skydome.rad] [-L lamps.oct] [-J jobs] [-C cachedir]\n"
	            "               [--dc-options O] [--elec-options O] [--dc-size N] [--elec-size N]\n"
	            "  -f FILE   psensd.conf: the zone's law, devices and [simulate] power curve\n"
	            "  -z ZONE   the zone (default the first)\n"
	            "  -c FILE   candidate poses: an id and a Radiance view a line\n"
	            "  --ceiling X0,X1,NX,Y0,Y1,NY,Z  candidate poses on a grid (with or instead of -c)\n"
	            "  --aims A,...  their aims: down (default) or TILT@AZIMUTH (degrees; the azimuth\n"
	            "            in the plan from +y toward +x)\n"
	            "  -d DIR    where each pose's DIR/id/dc_%%03d.hdr and elec.hdr are (default .)\n"
	            "  -g FILE   the work-plane grid's coefficients (rfluxmtx -I+ matrix)\n"
	            "  -e FILE   the grid's electric irradiance (rtrace -I+ lines)\n"
	            "  -w FILE   the weather (.wea or .epw)\n"
	            "  -s FILE   a sensor: a table or builtin:cosine, builtin:uniform (repeat);\n"
	            "            FILE@FILTER with its colour filter (wavelength, response; as\n"
	            "            psens -f), FILE@R,G,B with colour weights (as psens -R -G -B)\n"
	            "  -a LAW    a control law (repeat; default all five)\n"
	            "  -r DEG    the rotation step about the sensor axis (default 10: 36 rotations)\n"
	            "  -t FIG    the grid's figure: min, mean (default), pNN, points:i,j,...\n"
	            "  -T N      re-check the best N by the exact route (default 3)\n"
	            "  -n N      threads for the years (default 2)\n"
	            "  -p S      control period, s (default the zone's)\n"
	            "  -u H      hours below 90 %% of the target still ranked by energy\n"
	            "  -k DEG    the projection's cells in polar angle (default 2)\n"
	            "  -j        the whole table as JSON;  -o FILE  the JSON to a file\n"
	            "  -x FILE   the winner's results for psensd\n"
	            "  -E FILE   the winner's year as an EnergyPlus Schedule:File CSV\n"
	            "  -y FILE   the winner's year as a plain CSV\n"
	            "  -Z FILE   the winner's settings as a psensd.conf zone section\n"
	            "  -P FILE   the plan of the poses as a PNG\n"
	            "  -F FILE   the best sensor's sensitivity over its pose's fisheye, a PNG\n"
	            "  -q        only the best 10 rows\n"
	            "  rendering the missing pictures with Radiance, into the cache:\n"
	            "  -M OCT    the room's octree (lamps off) for rfluxmtx's coefficient pictures\n"
	            "  -K FILE   the sky patches' receiver file (#@rfluxmtx h=u / h=r1 lines)\n"
	            "  -L OCT    the room's octree with the lamps on, no daylight, for rpict\n"
	            "  -J N, --jobs N  renderers at once (default the cores)\n"
	            "  -C DIR    the cache (default $XDG_CACHE_HOME/psensd or ~/.cache/psensd)\n"
	            "  --dc-options O    rfluxmtx's options (default " PSD_PLACERENDER_DC_OPTIONS ")\n"
	            "  --elec-options O  rpict's options (default " PSD_PLACERENDER_ELEC_OPTIONS ")\n"
	            "  --dc-size N, --elec-size N  the pictures' size (default 64 and 128)\n"
	            "  -h, --help     this help;  -V, --version  the version\n");
}


static int parse_law(const char *name)
{
	for (int i = 0; psd_control_algorithm_names[i]; i++)
		if (!strcmp(name, psd_control_algorithm_names[i]))
			return i;
	return -1;
}

static int positive_int(const char *v, int lo, int hi, int *out)
{
	char *end;
	long x = strtol(v, &end, 10);
	if (end == v || *end || x < lo || x > hi)
		return -1;
	*out = (int)x;
	return 0;
}

/* A sensor as -s gives it: the table (or builtin), and after the last '@'
 * its colour filter file or its R,G,B weights; without one the luminous
 * weights.  -1 with err naming the filter's file and line. */
static int parse_sensor(struct opts *o, int k, char *err, size_t errlen)
{
	const char *spec = o->sens[k], *at = strrchr(spec, '@');
	double *w = o->coef[k];
	w[0] = PS_RGB_DEFAULT_R;
	w[1] = PS_RGB_DEFAULT_G;
	w[2] = PS_RGB_DEFAULT_B;
	if (!at) {
		snprintf(o->sens_path[k], sizeof o->sens_path[k], "%s", spec);
		return 0;
	}
	if ((size_t)(at - spec) >= sizeof o->sens_path[k] || at == spec)
		return snprintf(err, errlen, "-s %s: expected SENSOR@FILTER or SENSOR@R,G,B", spec), -1;
	memcpy(o->sens_path[k], spec, (size_t)(at - spec));
	o->sens_path[k][at - spec] = 0;
	{
		/* three numbers separated by commas: the weights */
		const char *q = at + 1;
		char *end;
		int n = 0;
		double v[3];
		while (n < 3) {
			v[n] = strtod(q, &end);
			if (end == q || !isfinite(v[n]))
				break;
			n++;
			q = end;
			if (n < 3 && *q != ',')
				break;
			if (n < 3)
				q++;
		}
		if (n == 3 && !*q) {
			if (!(v[0] >= 0 && v[1] >= 0 && v[2] >= 0) || v[0] + v[1] + v[2] <= 0)
				return snprintf(err, errlen, "-s %s: colour weights are not negative and not all 0", spec), -1;
			memcpy(w, v, sizeof v);
			return 0;
		}
	}
	{
		struct ps_err e;
		if (ps_filter_rgb(at + 1, w, &e) != 0)
			return snprintf(err, errlen, "-s %s: %s", spec, e.msg), -1;
	}
	return 0;
}

static void search_free(struct search *s)
{
	for (int i = 0; i < s->nposes; i++) {
		free(s->poses[i].row);
		free(s->poses[i].elec);
	}
	free(s->poses);
	for (int k = 0; s->sens && k < s->o->nsens; k++)
		ps_sensor_free(&s->sens[k]);
	free(s->sens);
	free(s->hrs.h);
	free(s->hrs.sky);
	free(s->hrs.task);
	free(s->hrs.pt_day);
	free(s->hrs.pt_elec);
	free(s->hrs.ideal);
	free(s->c);
}

int main(int argc, char **argv)
{
	static struct psd_config cf;
	enum { OPT_DC_OPTIONS = 1000, OPT_ELEC_OPTIONS, OPT_DC_SIZE, OPT_ELEC_SIZE, OPT_CEILING, OPT_AIMS };
	static const struct option longopts[] = { PS_CLI_LONGOPTS,
		                                   { "jobs", required_argument, NULL, 'J' },
		                                   { "dc-options", required_argument, NULL, OPT_DC_OPTIONS },
		                                   { "elec-options", required_argument, NULL, OPT_ELEC_OPTIONS },
		                                   { "dc-size", required_argument, NULL, OPT_DC_SIZE },
		                                   { "elec-size", required_argument, NULL, OPT_ELEC_SIZE },
		                                   { "ceiling", required_argument, NULL, OPT_CEILING },
		                                   { "aims", required_argument, NULL, OPT_AIMS },
		                                   { NULL, 0, NULL, 0 } };
	struct opts o = { .stat = "mean", .nrot = 36, .rot_step = 10, .top = 3, .threads = 2, .cell_theta = 2.0,
	                  .dir = ".", .max_below = -1, .dc_options = PSD_PLACERENDER_DC_OPTIONS,
	                  .elec_options = PSD_PLACERENDER_ELEC_OPTIONS, .dc_size = 64, .elec_size = 128 };
	struct psd_placerender_count rn;
	long cores = sysconf(_SC_NPROCESSORS_ONLN);
	struct search s;
	struct ps_gridmtx g;
	char err[1024], what[256];
	double t0 = psd_time_mono(), t_sky, t_proj, t_run;
	int ch, status = 1;
	while ((ch = getopt_long(argc, argv, "f:z:c:d:g:e:w:s:a:r:t:T:n:p:u:k:jo:x:E:y:Z:P:F:qM:K:L:J:C:hV", longopts, NULL)) != -1) {
		switch (ch) {
		case 'f': o.conf = optarg; break;
		case 'z': o.zone = optarg; break;
		case 'c': o.cands = optarg; break;
		case 'd': o.dir = optarg; break;
		case 'g': o.grid = optarg; break;
		case 'e': o.elec = optarg; break;
		case 'w': o.weather = optarg; break;
		case 's':
			if (o.nsens == PSD_PLACE_MAX_LIST) {
				fprintf(stderr, "psplace: -s: at most %d sensors\n", PSD_PLACE_MAX_LIST);
				return 2;
			}
			o.sens[o.nsens++] = optarg;
			break;
		case 'a': {
			int a = parse_law(optarg);
			if (a < 0 || o.nlaws == PSD_ALG_COUNT) {
				fprintf(stderr, "psplace: -a %s: a law is one of setpoint, closed-proportional, "
				                "open-proportional, integral-reset, switching\n", optarg);
				return 2;
			}
			o.laws[o.nlaws++] = a;
			break;
		}
		case 'r': {
			char *end;
			double v = strtod(optarg, &end), n = v > 0 ? 360.0 / v : 0;
			if (end == optarg || *end || !(v > 0) || v > 360 || fabs(n - round(n)) > 1e-9) {
				fprintf(stderr, "psplace: -r %s: a rotation step that divides 360 degrees\n", optarg);
				return 2;
			}
			o.rot_step = v;
			o.nrot = (int)round(n);
			break;
		}
		case 't': o.stat = optarg; break;
		case 'T':
			if (positive_int(optarg, 0, 1000, &o.top) != 0) {
				fprintf(stderr, "psplace: -T %s: 0 to 1000\n", optarg);
				return 2;
			}
			break;
		case 'n':
			if (positive_int(optarg, 1, 256, &o.threads) != 0) {
				fprintf(stderr, "psplace: -n %s: 1 to 256 threads\n", optarg);
				return 2;
			}
			break;
		case 'p':
		case 'u':
		case 'k': {
			char *end;
			double v = strtod(optarg, &end);
			if (end == optarg || *end || !(v > 0) || v > 86400) {
				fprintf(stderr, "psplace: -%c %s: a positive number\n", ch, optarg);
				return 2;
			}
			if (ch == 'p')
				o.period = v;
			else if (ch == 'u')
				o.max_below = v;
			else
				o.cell_theta = v;
			break;
		}
		case 'j': o.json = 1; break;
		case 'o': o.json_out = optarg; break;
		case 'x': o.results_out = optarg; break;
		case 'E': o.schedule = optarg; break;
		case 'y': o.csv = optarg; break;
		case 'Z': o.zone_out = optarg; break;
		case 'P': o.plan = optarg; break;
		case 'F': o.fisheye = optarg; break;
		case 'q': o.quiet = 1; break;
		case 'M': o.dc_octree = optarg; break;
		case 'K': o.receiver = optarg; break;
		case 'L': o.elec_octree = optarg; break;
		case 'C': o.cache = optarg; break;
		case OPT_DC_OPTIONS: o.dc_options = optarg; break;
		case OPT_ELEC_OPTIONS: o.elec_options = optarg; break;
		case OPT_CEILING: o.ceiling = optarg; break;
		case OPT_AIMS: o.aims = optarg; break;
		case 'J':
		case OPT_DC_SIZE:
		case OPT_ELEC_SIZE: {
			int v;
			if (positive_int(optarg, 1, ch == 'J' ? 256 : 8192, &v) != 0) {
				fprintf(stderr, "psplace: %s %s: 1 to %d\n", ch == 'J' ? "-J" : ch == OPT_DC_SIZE ? "--dc-size"
				        : "--elec-size", optarg, ch == 'J' ? 256 : 8192);
				return 2;
			}
			*(ch == 'J' ? &o.jobs : ch == OPT_DC_SIZE ? &o.dc_size : &o.elec_size) = v;
			break;
		}
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psplace");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc || !o.conf || (!o.cands && !o.ceiling) || !o.grid || !o.elec || !o.weather) {
		usage(stderr);
		return 2;
	}
	if (!o.nsens)
		o.sens[o.nsens++] = "builtin:cosine";
	if (!o.jobs)
		o.jobs = cores > 0 ? (cores > 256 ? 256 : (int)cores) : 1;
	if (!o.nlaws)
		for (int a = 0; a < PSD_ALG_COUNT; a++)
			o.laws[o.nlaws++] = a;
	psd_log_init(1, 6, "psplace");
	memset(&s, 0, sizeof s);
	memset(&g, 0, sizeof g);
	s.o = &o;
	s.cf = &cf;
	pthread_mutex_init(&s.lock, NULL);
	if (psd_config_load_keys(&cf, o.conf) != 0) {
		for (size_t i = 0; i < cf.conf.nerrors; i++)
			fprintf(stderr, "psplace: %s\n", cf.conf.errors[i]);
		psd_config_free(&cf);
		return 1;
	}
	{
		int zi = o.zone ? psd_config_zone(&cf, o.zone) : cf.nzone ? 0 : -1;
		if (zi < 0) {
			fprintf(stderr, "psplace: %s: no zone %s\n", o.conf, o.zone ? o.zone : "at all");
			goto out;
		}
		s.zc = &cf.zone[zi];
	}
	if (o.max_below < 0)
		o.max_below = 0.01 * (cf.occ_to - cf.occ_from) / 3600.0 * 365;   /* 1 % of the occupied hours */
	s.ao.period = o.period > 0 ? o.period : s.zc->period;
	s.ao.occ_start = cf.occ_from;
	s.ao.occ_end = cf.occ_to;
	s.ao.dated = 1;
	s.ao.no_estimate = 1;   /* the estimate's error statistics are not scored */
	if (psd_annual_devices(&cf, s.zc, &s.ao, what, sizeof what, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: zone %s: %s\n", s.zc->name, err);
		goto out;
	}
	s.sens = calloc((size_t)o.nsens, sizeof *s.sens);
	if (!s.sens)
		goto oom;
	for (int k = 0; k < o.nsens; k++) {
		struct ps_err e;
		if (parse_sensor(&o, k, err, sizeof err) != 0) {
			fprintf(stderr, "psplace: %s\n", err);
			goto out;
		}
		if (ps_sensor_open(&s.sens[k], o.sens_path[k], &e) != 0) {
			fprintf(stderr, "psplace: -s %s: %s\n", o.sens[k], e.msg);
			goto out;
		}
	}
	/* cells in polar angle no coarser than half a table's finest step (a
	 * scan spreads each cell ring over two rows of every table step) */
	s.cell_theta = o.cell_theta;
	s.theta_max = 0;
	for (int k = 0; k < o.nsens; k++)
		if (ps_sensor_extent(&s.sens[k]) * 180.0 / M_PI > s.theta_max)
			s.theta_max = ps_sensor_extent(&s.sens[k]) * 180.0 / M_PI;
	s.theta_max = s.theta_max + o.cell_theta > 180 ? 180 : s.theta_max + o.cell_theta;
	for (int k = 0; k < o.nsens; k++)
		if (s.sens[k].kind == PS_SENS_TABLE)
			for (int i = 0; i < s.sens[k].nt; i++) {
				double half = 0.5 * (s.sens[k].tb[i + 1] - s.sens[k].tb[i]) * 180.0 / M_PI;
				if (half > 0 && half < s.cell_theta)
					s.cell_theta = half;
			}
	{
		struct ps_err e;
		double *lux, *scratch;
		if (ps_gridmtx_read(&g, o.grid, &e) != 0) {
			fprintf(stderr, "psplace: %s\n", e.msg);
			goto out;
		}
		if (psd_placeyear_check(o.stat, g.npoints, err, sizeof err) != 0) {
			fprintf(stderr, "psplace: %s\n", err);
			goto out;
		}
		lux = malloc((size_t)g.npoints * sizeof *lux);
		scratch = malloc((size_t)g.npoints * sizeof *scratch);
		if (!lux || !scratch) {
			free(lux);
			free(scratch);
			goto oom;
		}
		if (ps_gridmtx_elec_read(o.elec, g.npoints, lux, &e) != 0) {
			fprintf(stderr, "psplace: %s\n", e.msg);
			free(lux);
			free(scratch);
			goto out;
		}
		s.elec_task = psd_placeyear_stat(o.stat, lux, g.npoints, scratch);
		s.hrs.pt_elec = lux;
		free(scratch);
		s.npatch = g.npatch;
		s.mf = g.mf;
	}
	if ((o.cands && psd_placeset_read(&s, err, sizeof err) != 0) ||
	    (o.ceiling && psd_placeset_grid(&s, err, sizeof err) != 0)) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (psd_placerender_all(&s, &rn, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (o.dc_octree || o.elec_octree)
		fprintf(stderr, "psplace: rendered %d coefficient set(s) and %d electric picture(s) with %d job(s); "
		        "%d and %d from the cache\n", rn.dc_rendered, rn.elec_rendered, o.jobs, rn.dc_cached, rn.elec_cached);
	if (psd_placeyear_hours(&s, &g, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	t_sky = psd_time_mono();
	if (psd_placerun_project(&s, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	t_proj = psd_time_mono();
	s.nc = (size_t)s.nposes * (size_t)o.nrot * (size_t)o.nsens * (size_t)o.nlaws;
	s.c = calloc(s.nc, sizeof *s.c);
	if (!s.c)
		goto oom;
	{
		size_t i = 0;
		for (int p = 0; p < s.nposes; p++)
			for (int r = 0; r < o.nrot; r++)
				for (int k = 0; k < o.nsens; k++)
					for (int a = 0; a < o.nlaws; a++)
						s.c[i++] = (struct combo){ .pose = p, .rot = r, .sens = k, .law = a };
	}
	psd_placerun_all(&s);
	t_run = psd_time_mono();
	psd_placerun_rank(&s);
	/* the best again by the exact route */
	for (size_t i = 0; i < (size_t)o.top && i < s.nc; i++) {
		struct combo *k = &s.c[i], x;
		double *row = malloc((size_t)s.npatch * 3 * sizeof *row), elec;
		if (!row)
			goto oom;
		if (k->fail || psd_placeset_exact(&s, &s.poses[k->pose], k->sens, psd_placerun_rot_deg(&s, k->rot), row, &elec, err,
		                         sizeof err) != 0) {
			if (!k->fail)
				fprintf(stderr, "psplace: %s\n", err);
			free(row);
			continue;
		}
		x = *k;
		if (psd_placerun_row(&s, &x, 1, row, elec, NULL) == 0) {
			k->exact = 1;
			k->exact_sensor_err = 100 * (k->sensor_sum / x.sensor_sum - 1);
			k->exact_energy_err = 100 * (k->a.energy_h - x.a.energy_h) / k->a.occ_h;
		}
		free(row);
	}
	{
		double t_end = psd_time_mono();
		if (o.json_out) {
			FILE *fp = fopen(o.json_out, "w");
			if (!fp || psd_placeout_json(&s, fp, t_end - t0) != 0 || fclose(fp) != 0) {
				fprintf(stderr, "psplace: %s: %s\n", o.json_out, strerror(errno));
				goto out;
			}
		}
		if (o.json) {
			if (psd_placeout_json(&s, stdout, t_end - t0) != 0)
				goto out;
		} else {
			printf("psplace: zone %s, %d poses x %d rotations x %d sensors x %d laws = %zu combinations,\n"
			       "  %zu hours with light of %s, the grid's %s (%d points; %.1f lx at full output),\n"
			       "  target %g lx, %s, a step every %g s\n",
			       s.zc->name, s.nposes, o.nrot, o.nsens, o.nlaws, s.nc, s.hrs.n, o.weather, o.stat, g.npoints,
			       s.elec_task, s.zc->ctl.target_lux, what, s.ao.period);
			psd_placeout_table(&s, o.quiet ? 10 : 40);
			for (size_t i = 0; i < (size_t)o.top && i < s.nc; i++)
				if (s.c[i].exact)
					printf("exact route, rank %zu: the year's sensor signal %+.3f %% by the projection, "
					       "energy %+.3f points\n", i + 1, s.c[i].exact_sensor_err, s.c[i].exact_energy_err);
			printf("time: %.3f s: sky and grid %.3f s, projections %.3f s, %zu years %.3f s (%.3f ms each "
			       "on %d threads), exact re-checks %.3f s\n", t_end - t0, t_sky - t0, t_proj - t_sky, s.nc,
			       t_run - t_proj, 1000 * (t_run - t_proj) / (double)s.nc, o.threads, t_end - t_run);
		}
	}
	if (s.failed)
		fprintf(stderr, "psplace: %d combination(s) could not run the year\n", s.failed);
	if (s.nc && !s.c[0].fail && psd_placeout_exports(&s, &s.c[0], err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (o.fisheye && s.nc && psd_placeout_fisheye(&s, &s.c[0], o.fisheye, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (o.plan && psd_placeout_plan(&s, o.plan, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	status = 0;
	goto out;
oom:
	fprintf(stderr, "psplace: out of memory\n");
out:
	ps_gridmtx_free(&g);
	search_free(&s);
	psd_config_free(&cf);
	return status;
}

