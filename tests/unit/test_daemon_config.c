/* SPDX-License-Identifier: ISC */
/* psensd.conf: devices, points and zones; every error with its line, all in
 * one pass; the zone shorthand; outputs shared by two zones refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>

#define assert_near(a, b, tol) assert_true(fabs((double)(a) - (double)(b)) <= (tol))

#include "config.h"

static struct psd_config cf;

static int has_error(const char *text)
{
	for (size_t i = 0; i < cf.conf.nerrors; i++)
		if (strstr(cf.conf.errors[i], text))
			return 1;
	return 0;
}

static void points_and_zones(void **state)
{
	(void)state;
	const char *text = "[psensd]\nresults = r\nperiod = 30\nstuck_after = 600\n"
	                   "[device io]\ndriver = loopback\ngain = 0.5\n"
	                   "[point s]\ndevice = io\nrole = sensor\nvalid_min = 0.05\n"
	                   "[point d]\ndevice = io\nrole = dim\n"
	                   "[point r1]\ndevice = io\nrole = relay\n"
	                   "[point b]\ndevice = io\nrole = input\naction = override\noccupied = 07:00-08:00\n"
	                   "[zone a]\nsensor = s\ndim = d\nrelay = r1\ninput = b\ntarget_lux = 400\n"
	                   "[zone z2]\ndevice = io\nperiod = 5\n";
	assert_int_equal(psd_config_load_string(&cf, text, "t.conf"), 0);
	assert_int_equal(cf.ndev, 1);
	assert_string_equal(cf.dev[0].drv->name, "loopback");
	/* the driver's keys go to the driver, the daemon's stay */
	assert_int_equal(cf.dev[0].opts.n, 1);
	assert_string_equal(cf.dev[0].opts.v[0].key, "gain");
	assert_int_equal(cf.dev[0].opts.v[0].line, 7);
	assert_int_equal(cf.npt, 6);   /* four named, two implicit for z2 */
	assert_near(cf.pt[0].min, 0.05, 0);
	assert_near(cf.pt[0].max, 9.9, 0);
	assert_int_equal(cf.pt[3].action, PSD_ACT_OVERRIDE);
	assert_int_equal(cf.pt[3].opts.n, 1);   /* occupied: the loopback's key */
	assert_int_equal(cf.nzone, 2);
	assert_int_equal(cf.zone[0].ndim, 1);
	assert_int_equal(cf.zone[0].nrelay, 1);
	assert_int_equal(cf.zone[0].ninput, 1);
	assert_near(cf.zone[0].period, 30, 0);
	assert_near(cf.zone[0].stale_after, 75, 1e-12);   /* 2.5 periods */
	assert_near(cf.zone[0].stuck_after, 600, 0);
	assert_near(cf.zone[0].ctl.target_lux, 400, 0);
	assert_string_equal(cf.pt[cf.zone[1].sensor].name, "io.sensor");
	assert_string_equal(cf.pt[cf.zone[1].dim[0]].name, "io.dim");
	assert_near(cf.zone[1].period, 5, 0);
	psd_config_free(&cf);
}

static void every_error_in_one_pass(void **state)
{
	(void)state;
	const char *text = "[psensd]\nperiod = 0\nsocket_mode = 0666\n"        /* 2, 3 */
	                   "[device io]\ndriver = nosuch\n"                    /* 5 */
	                   "[device io]\ndriver = loopback\n"                  /* 6 */
	                   "[point p]\ndevice = nodev\nrole = lamp\n"          /* 9, 10 */
	                   "[point q]\nrole = sensor\naction = occupancy\n"    /* 11..13 */
	                   "[zone a]\nsensor = p\ndim = q\ntypo = 1\n"         /* 14..17 */
	                   "[zone a]\n"                                        /* 18 */
	                   "[bogus]\n";                                        /* 19 */
	assert_int_equal(psd_config_load_string(&cf, text, "bad.conf"), -1);
	assert_true(has_error("bad.conf:2: period: 0 s is shorter than 0.1 s"));
	assert_true(has_error("bad.conf:3: socket_mode: '0666'"));
	assert_true(has_error("bad.conf:5: driver: no driver 'nosuch'"));
	assert_true(has_error("bad.conf:6: [device io] is defined twice"));
	assert_true(has_error("bad.conf:9: device: no [device nodev]"));
	assert_true(has_error("bad.conf:10: role: 'lamp' is not"));
	assert_true(has_error("bad.conf:11: [point q] needs 'device'"));
	assert_true(has_error("bad.conf:13: action: only an input point has an action"));
	assert_true(has_error("bad.conf:16: dim: point q has role sensor, not dim"));
	assert_true(has_error("bad.conf:17: unknown key 'typo' in [zone a]"));
	assert_true(has_error("bad.conf:18: [zone a] is defined twice"));
	assert_true(has_error("bad.conf:19: unknown section [bogus]"));
	assert_true(has_error("needs 'results'"));
	assert_true(cf.conf.nerrors >= 13);
	psd_config_free(&cf);
}

/* A bad or missing role is one error: the zones that name the point, and
 * the driver's keys that depend on the role, say nothing more ("role ?"). */
static void one_bad_role_one_error(void **state)
{
	(void)state;
	const char *text = "[psensd]\nresults = r\n"
	                   "[device io]\ndriver = loopback\n"
	                   "[point s]\ndevice = io\nrole = sensr\nvalid_min = 0.05\n"   /* 5..8 */
	                   "[point d]\ndevice = io\nrole = dim\n"
	                   "[point t]\ndevice = io\n"                                    /* 12 */
	                   "[zone z]\nsensor = s\ndim = d\ntask = t\n";
	assert_int_equal(psd_config_load_string(&cf, text, "role.conf"), -1);
	for (size_t i = 0; i < cf.conf.nerrors; i++)
		print_message("# %s\n", cf.conf.errors[i]);
	assert_true(has_error("role.conf:7: role: 'sensr' is not"));
	assert_true(has_error("role.conf:12: [point t] needs 'role'"));
	assert_int_equal(cf.conf.nerrors, 2);
	assert_false(has_error("?"));
	psd_config_free(&cf);
}

static void shared_outputs_and_names(void **state)
{
	(void)state;
	const char *text = "[psensd]\nresults = r\n[device io]\ndriver = loopback\n"
	                   "[zone a]\ndevice = io\n[zone b]\ndevice = io\n"
	                   "[zone c d]\ndevice = io\n";
	assert_int_equal(psd_config_load_string(&cf, text, "s.conf"), -1);
	assert_true(has_error("s.conf:7: [zone b]: output io.dim already belongs to zone a"));
	assert_true(has_error("s.conf:9: [zone c d]: a name is 1 to 47"));
	psd_config_free(&cf);
}

static void missing_file(void **state)
{
	(void)state;
	assert_int_equal(psd_config_load(&cf, "/nonexistent/psensd.conf"), -1);
	assert_int_equal(cf.conf.nerrors, 1);
	assert_non_null(strstr(cf.conf.errors[0], "/nonexistent/psensd.conf"));
	psd_config_free(&cf);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(points_and_zones),
		cmocka_unit_test(every_error_in_one_pass),
		cmocka_unit_test(one_bad_role_one_error),
		cmocka_unit_test(shared_outputs_and_names),
		cmocka_unit_test(missing_file),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
