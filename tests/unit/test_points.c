/* SPDX-License-Identifier: ISC */
/* The point model (daemon/points.c) behind every front end: an engine of
 * two zones on the file driver (office with a task meter and an occupancy
 * state, hall with neither; [simulate] lamp_watts for kWh) is read through
 * the three front ends as a client sees them, and each lists exactly the
 * points the table says the zone has: the control socket's status (each
 * zone's "points"), Home Assistant discovery (one entity per point, an
 * empty config for a point the zone lacks), and the BACnet device's
 * Object_List (asked over UDP, every object's Object_Name read back and
 * matched to "<zone> <point name>").  Then the Prometheus text: its
 * series against the status values, and the energy against the
 * integral of the level over an hour (light-output hours as seconds,
 * Prometheus' base unit).  Last, the writable points' writes reach the
 * engine's control. */
#include <arpa/inet.h>
#include <json-c/json.h>
#include <math.h>
#include <netinet/in.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <cmocka.h>

#include "bacnet.h"
#include "bactag.h"
#include "cmdtab.h"
#include "loop.h"
#include "mqttmsg.h"
#include "points.h"
#include "results.h"
#include "scene.h"

/* |a - b| <= eps (this cmocka has no assert_double_equal) */
#define near(a, b, eps)                                                                  \
	do {                                                                             \
		double a_ = (a), b_ = (b);                                               \
		if (!(fabs(a_ - b_) <= (eps)))                                           \
			fail_msg("%s = %.17g, not %.17g", #a, a_, b_);                   \
	} while (0)

static char dir[] = "/tmp/psd-points-XXXXXX";
static struct psd_daemon d;

static void put(const char *name, const char *text)
{
	char path[128];
	FILE *f;
	snprintf(path, sizeof path, "%s/%s", dir, name);
	f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
}

static int setup(void **state)
{
	struct psd_config *cf = calloc(1, sizeof *cf);
	char text[2048], err[512];
	(void)state;
	if (!cf || !mkdtemp(dir))
		return -1;
	put("s1", "1.25\n");
	put("t1", "310\n");
	put("s2", "0.8\n");
	{   /* the simulation's results: one daylight and one electric condition */
		struct ps_result_cond c[2] = {
			{ "d1", PS_COND_DAYLIGHT, "03-18", 43200, 1, 5.0, 6.0, 1074.0, 200.0, 0.01 },
			{ "e", PS_COND_ELECTRIC, "", -1, 1, 1.0, 7.0, 1253.0, 1050.0, 0.0 },
		};
		struct ps_results r = { .scene = "x.scene", .scene_hash = "abc", .sensitivity = "builtin:cosine",
			                .reading = "linear", .rgb = { 0.2, 0.7, 0.1 }, .cond = c, .ncond = 2 };
		struct ps_err e;
		snprintf(text, sizeof text, "%s/r.results", dir);
		ps_results_summarise(&r);
		if (ps_results_write(&r, text, &e) != 0)
			return -1;
	}
	snprintf(text, sizeof text,
	         "[psensd]\nresults = %s/r.results\nperiod = 60\nsafe_level = 1\n[simulate]\nlamp_watts = 40\npower_at_min = 0.2\n"
	         "[device files]\ndriver = file\ndir = %s\n"
	         "[point s1]\ndevice = files\nrole = sensor\npath = s1\n"
	         "[point t1]\ndevice = files\nrole = task\npath = t1\n"
	         "[point d1]\ndevice = files\nrole = dim\npath = d1\n"
	         "[point s2]\ndevice = files\nrole = sensor\npath = s2\n"
	         "[point d2]\ndevice = files\nrole = dim\npath = d2\n"
	         "[zone office]\nsensor = s1\ntask = t1\ndim = d1\ntarget_lux = 500\nsensor_gain = 0.5\n"
	         "[zone hall]\nsensor = s2\ndim = d2\ntarget_lux = 300\nsensor_gain = 0.5\n",
	         dir, dir);
	if (psd_config_load_string(cf, text, "t.conf") != 0) {
		fprintf(stderr, "%s\n", cf->conf.nerrors ? cf->conf.errors[0] : "config");
		return -1;
	}
	if (psd_engine_open(&d.engine, cf, 0, 1, NULL, err, sizeof err) != 0) {
		fprintf(stderr, "%s\n", err);
		return -1;
	}
	d.config_path = "t.conf";
	d.clock.simulated = 1;
	d.clock.now = 0;
	psd_engine_step(&d.engine, 0);
	/* the occupancy input's state as the engine keeps it (the file driver
	 * has no input points) */
	d.engine.zone[0].occupancy = 1;
	psd_points_update(&d.points, &d.engine, 0);
	psd_points_update(&d.points, &d.engine, 3600);
	d.clock.now = 3600;
	return 0;
}

static int teardown(void **state)
{
	struct psd_config *cf;
	static const char *const files[] = { "s1", "t1", "s2", "d1", "d2", "r.results" };
	char path[128];
	(void)state;
	if (d.engine.cf && (cf = psd_engine_close(&d.engine))) {
		psd_config_free(cf);
		free(cf);
	}
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		snprintf(path, sizeof path, "%s/%s", dir, files[i]);
		unlink(path);
	}
	rmdir(dir);
	return 0;
}

/* The table must make the zones differ, or the test below proves little. */
static void the_zones_differ(void **state)
{
	(void)state;
	assert_true(psd_points_has(&d.engine, 0, (size_t)psd_points_find("task_lux")));
	assert_false(psd_points_has(&d.engine, 1, (size_t)psd_points_find("task_lux")));
	assert_int_equal(psd_points_occupancy(&d.engine.zone[0]), 1);
	assert_int_equal(psd_points_occupancy(&d.engine.zone[1]), -1);
	assert_true(psd_points_has(&d.engine, 0, (size_t)psd_points_find("occupied")));
	assert_false(psd_points_has(&d.engine, 1, (size_t)psd_points_find("occupied")));
	assert_true(psd_points_has(&d.engine, 1, (size_t)psd_points_find("energy_kwh")));
	assert_true(psd_points_has(&d.engine, 0, (size_t)psd_points_find("ratio")));
}

static json_object *status(void)
{
	struct psd_ctl_reply reply = { 0 };
	char line[] = "status";
	json_object *o;
	psd_cmdtab_request(&d, line, &reply);
	o = json_tokener_parse(reply.text);
	psd_ctlsock_reply_free(&reply);
	assert_non_null(o);
	return o;
}

static void status_lists_the_points(void **state)
{
	json_object *o = status(), *zones, *z, *pts, *v;
	(void)state;
	assert_true(json_object_object_get_ex(o, "zones", &zones));
	assert_int_equal(json_object_array_length(zones), 2);
	for (size_t zi = 0; zi < 2; zi++) {
		int n = 0;
		z = json_object_array_get_idx(zones, zi);
		assert_true(json_object_object_get_ex(z, "points", &pts));
		for (size_t i = 0; i < psd_points_count(); i++) {
			int has = psd_points_has(&d.engine, zi, i);
			assert_int_equal(json_object_object_get_ex(pts, psd_points_def(i)->key, &v), has);
			n += has;
		}
		assert_int_equal(json_object_object_length(pts), n);   /* and nothing else */
	}
	json_object_put(o);
}

static int has_in(void *user, size_t i)
{
	return psd_points_has(&d.engine, *(size_t *)user, i);
}

static void discovery_lists_the_points(void **state)
{
	char topic[256], payload[4096];
	(void)state;
	for (size_t zi = 0; zi < 2; zi++) {
		int seen[64] = { 0 }, pt, k;
		for (k = 0; psd_mqttmsg_discovery(k, "ha", "site", d.engine.zone[zi].zc->name, has_in, &zi, 1, topic,
		                                  sizeof topic, payload, sizeof payload, &pt) == 0;
		     k++) {
			if (pt < 0)
				continue;   /* the override's number */
			assert_true(pt < 64);
			seen[pt]++;
			if (payload[0]) {   /* its name is the point's */
				char want[128];
				snprintf(want, sizeof want, "\"name\":\"%s %s\"", d.engine.zone[zi].zc->name,
				         psd_points_def((size_t)pt)->name);
				assert_non_null(strstr(payload, want));
			}
			assert_int_equal(payload[0] != 0, psd_points_has(&d.engine, zi, (size_t)pt));
		}
		for (size_t i = 0; i < psd_points_count(); i++)
			assert_int_equal(seen[i], 1);
	}
}

/* ReadProperty of (type, instance) prop from the BACnet server over UDP:
 * the value's octets (after [3] opening) into v, their count. */
static size_t read_property(void *b, int cs, const struct sockaddr_in *to, uint32_t type,
                            uint32_t inst, uint32_t prop, uint8_t *v, size_t cap)
{
	uint8_t req[64], rep[1600];
	struct psd_bacbuf q = { req, sizeof req, 0, 0 };
	static const uint8_t head[] = { 0x81, 0x0a, 0, 0, 0x01, 0x04, 0x00, 0x05, 0x01, 0x0c };
	struct pollfd pfd;
	ssize_t n;
	size_t pos;
	psd_bactag_put_raw(&q, head, sizeof head);
	psd_bactag_put_objectid(&q, 0, type, inst);
	psd_bactag_put_enum(&q, 1, prop);
	req[3] = (uint8_t)q.len;
	assert_int_equal(sendto(cs, req, q.len, 0, (const struct sockaddr *)to, sizeof *to), (ssize_t)q.len);
	psd_bacnet_frontend.pollfds(b, &pfd, 1);
	pfd.revents = POLLIN;
	usleep(2000);
	psd_bacnet_frontend.service(b, &pfd, 1, 3600);
	n = recv(cs, rep, sizeof rep, 0);
	assert_true(n > 9);
	assert_int_equal(rep[6], 0x30);   /* a ComplexACK */
	/* after the object identifier [0] and the property [1]: [3] opening */
	pos = 9;
	{
		struct psd_bactag t;
		assert_int_equal(psd_bactag_read(rep, (size_t)n, &pos, &t), 0);
		assert_int_equal(psd_bactag_read(rep, (size_t)n, &pos, &t), 0);
		assert_int_equal(psd_bactag_read(rep, (size_t)n, &pos, &t), 0);
		assert_true(t.opening && t.number == 3);
	}
	assert_true((size_t)n - pos - 1 <= cap);
	memcpy(v, rep + pos, (size_t)n - pos - 1);   /* less the [3] closing */
	return (size_t)n - pos - 1;
}

static void bacnet_lists_the_points(void **state)
{
	struct psd_bacnet_conf c = { .enabled = 1, .bind = "127.0.0.1", .port = 0, .instance = 77, .name = "t",
		                     .vendor_id = 65535, .writes = PSD_BACCONF_NONE, .hold = 60, .rate = 1e6 };
	char err[256], names[64][128];
	uint8_t v[1500];
	struct sockaddr_in to;
	socklen_t tl = sizeof to;
	struct pollfd pfd;
	static struct psd_config cf;   /* only its [bacnet] */
	const struct psd_frontend_env env = { .cf = &cf, .engine = &d.engine, .points = &d.points,
	                                      .override = psd_cmdtab_override, .release = psd_cmdtab_release };
	void *b;
	int cs = socket(AF_INET, SOCK_DGRAM, 0);
	size_t n, pos = 0, nobj = 0, want = 1;
	(void)state;
	cf.bacnet = c;
	assert_non_null(b = psd_bacnet_frontend.start(&env, err, sizeof err));
	assert_true(cs >= 0);
	psd_bacnet_frontend.pollfds(b, &pfd, 1);
	assert_int_equal(getsockname(pfd.fd, (struct sockaddr *)&to, &tl), 0);
	n = read_property(b, cs, &to, 8, 77, 76 /* Object_List */, v, sizeof v);
	while (pos < n) {
		struct psd_bactag t;
		uint32_t type, inst;
		uint8_t s[200];
		size_t sn, sp = 0;
		assert_int_equal(psd_bactag_read(v, n, &pos, &t), 0);
		assert_int_equal(psd_bactag_objectid(&t, &type, &inst), 0);
		assert_true(nobj < 64);
		sn = read_property(b, cs, &to, type, inst, 77 /* Object_Name */, s, sizeof s);
		assert_int_equal(psd_bactag_read(s, sn, &sp, &t), 0);
		assert_true(t.len >= 1 && t.len - 1 < sizeof names[0]);
		memcpy(names[nobj], t.data + 1, t.len - 1);   /* after the character set */
		names[nobj++][t.len - 1] = 0;
	}
	for (size_t zi = 0; zi < 2; zi++)
		for (size_t i = 0; i < psd_points_count(); i++) {
			char name[128];
			int found = 0;
			snprintf(name, sizeof name, "%s %s", d.engine.zone[zi].zc->name, psd_points_def(i)->name);
			for (size_t k = 0; k < nobj; k++)
				found += strcmp(names[k], name) == 0;
			assert_int_equal(found, psd_points_has(&d.engine, zi, i));
			want += (size_t)found;
		}
	assert_int_equal(nobj, want);   /* the Device and the points, nothing else */
	close(cs);
	psd_bacnet_frontend.stop(b);
}

/* A value of the Prometheus text: the series' number, NAN when absent. */
static double series(const char *text, const char *head)
{
	const char *p = text;
	size_t n = strlen(head);
	for (; (p = strstr(p, head)); p += n)
		if (p == text || p[-1] == '\n')
			return strtod(p + n, NULL);
	return NAN;
}

static void prometheus_matches_status(void **state)
{
	char *text = psd_points_prometheus(&d.points, &d.engine, 3600);
	json_object *o = status(), *zones, *pts, *v;
	double level, hours;
	(void)state;
	assert_non_null(text);
	assert_non_null(strstr(text, "# TYPE psensd_est_task_lux gauge\n"));
	assert_non_null(strstr(text, "# HELP psensd_est_task_lux "));
	json_object_object_get_ex(o, "zones", &zones);
	json_object_object_get_ex(json_object_array_get_idx(zones, 0), "points", &pts);
	json_object_object_get_ex(pts, "task_lux", &v);
	near(series(text, "psensd_task_lux{zone=\"office\"} "), 310, 0);
	near(series(text, "psensd_task_lux{zone=\"office\"} "), json_object_get_double(v), 0);
	assert_true(isnan(series(text, "psensd_task_lux{zone=\"hall\"} ")));
	json_object_object_get_ex(pts, "level", &v);
	level = json_object_get_double(v);
	near(series(text, "psensd_level{zone=\"office\"} "), level, 1e-9);
	/* the multi-state: one series per state, the one in force 1 */
	near(series(text, "psensd_state{zone=\"office\",state=\"auto\"} "), 1, 0);
	near(series(text, "psensd_state{zone=\"office\",state=\"fault\"} "), 0, 0);
	/* an hour at the level: level/100 light-output hours; kWh through the
	 * power curve 0.2 at the file driver's least level (instant ballast:
	 * proportional to light), 40 W */
	hours = series(text, "psensd_output_seconds{zone=\"office\"} ") / 3600;
	near(hours, level / 100, 1e-9);
	near(series(text, "psensd_energy_kwh{zone=\"office\"} "), hours * 40 / 1000, 1e-9);
	free(text);
	json_object_put(o);
}

/* The writable points: the configured value, a write that moves the
 * engine, the range refused.  Daylight control off holds the level that
 * meets the target with no daylight: target / the electric task lux at
 * full output (the results' electric condition: 1253 lx), whatever the
 * daylight. */
static void writes_reach_the_engine(void **state)
{
	int target = psd_points_find("target_lux"), day = psd_points_find("daylighting");
	int hold = psd_points_find("vacancy_hold"), level = psd_points_find("level");
	struct psd_zone *hall = &d.engine.zone[1];
	char err[256];
	double v;
	(void)state;
	assert_true(target >= 0 && day >= 0 && hold >= 0 && level >= 0);
	assert_int_equal(psd_points_default(&d.engine, 1, (size_t)target, &v), 0);
	near(v, 300, 0);
	assert_int_equal(psd_points_default(&d.engine, 1, (size_t)day, &v), 0);
	near(v, 1, 0);
	assert_int_equal(psd_points_default(&d.engine, 1, (size_t)level, &v), -1);
	/* the hall has no occupancy input: no vacancy hold to write */
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)hold, 600, err, sizeof err), -1);
	assert_int_equal(psd_points_write(&d.engine, 0, (size_t)hold, 600, err, sizeof err), 0);
	near(d.engine.zone[0].occ.hold, 600, 0);
	assert_int_equal(psd_points_write(&d.engine, 0, (size_t)hold, 90000, err, sizeof err), -1);
	assert_non_null(strstr(err, "outside 0 to 86400"));
	/* the target: out of range refused, in range the control's */
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)target, 5001, err, sizeof err), -1);
	near(hall->ctl.target_lux, 300, 0);
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)target, 420, err, sizeof err), 0);
	assert_int_equal(psd_points_value(&d.points, &d.engine, 1, (size_t)target, 3600, &v), 0);
	near(v, 420, 0);
	/* daylight control off: 420 / 1253 at the next step */
	near(hall->ctl.elec_task_lux, 1253, 1e-9);
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)day, 2, err, sizeof err), -1);
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)day, 0, err, sizeof err), 0);
	assert_int_equal(psd_points_value(&d.points, &d.engine, 1, (size_t)day, 3600, &v), 0);
	near(v, 0, 0);
	psd_engine_step(&d.engine, 3660);
	near(hall->level, 420.0 / 1253, 1e-12);
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)target, 630, err, sizeof err), 0);
	psd_engine_step(&d.engine, 3720);
	near(hall->level, 630.0 / 1253, 1e-12);
	/* on again: the control's own level (the daylight meets more of it) */
	assert_int_equal(psd_points_write(&d.engine, 1, (size_t)day, 1, err, sizeof err), 0);
	psd_engine_step(&d.engine, 3780);
	assert_true(hall->level < 630.0 / 1253 - 0.01);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(the_zones_differ),
		cmocka_unit_test(status_lists_the_points),
		cmocka_unit_test(discovery_lists_the_points),
		cmocka_unit_test(bacnet_lists_the_points),
		cmocka_unit_test(prometheus_matches_status),
		cmocka_unit_test(writes_reach_the_engine),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
