/* SPDX-License-Identifier: ISC */
/* The Modbus driver against a libmodbus server on 127.0.0.1 in a thread:
 * register values, exceptions, silence, garbage, a lost connection and the
 * reconnect backoff on the caller's clock, polled points and input events.
 * The server's misbehaviour is switched by the test (the libmodbus
 * unit-test-server's special addresses, as a mode). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <errno.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#ifdef PS_WITH_MODBUS
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <modbus.h>

#include "driver.h"
#include "helpers/test_opts.h"
#include "time.h"

extern const struct ps_driver ps_driver_modbus;

enum mode { NORMAL, EXCEPTION, SILENT, HANGUP, GARBAGE };

struct server {
	pthread_t th;
	modbus_t *ctx;
	modbus_mapping_t *map;
	int listen_fd, port;
	atomic_int mode, stop, accepted, requests;
	int running;
};

static struct server srv;

static void *serve(void *arg)
{
	struct server *s = arg;
	int client = -1;
	uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
	(void)arg;
	while (!atomic_load(&s->stop)) {
		struct pollfd p = { client >= 0 ? client : s->listen_fd, POLLIN, 0 };
		int rc;
		if (poll(&p, 1, 20) <= 0)
			continue;
		if (client < 0) {
			client = accept(s->listen_fd, NULL, NULL);
			if (client >= 0)
				atomic_fetch_add(&s->accepted, 1);
			continue;
		}
		modbus_set_socket(s->ctx, client);
		rc = modbus_receive(s->ctx, q);
		if (rc <= 0) {
			if (rc < 0) {
				close(client);
				client = -1;
			}
			continue;
		}
		atomic_fetch_add(&s->requests, 1);
		switch (atomic_load(&s->mode)) {
		case NORMAL: modbus_reply(s->ctx, q, rc, s->map); break;
		case EXCEPTION: modbus_reply_exception(s->ctx, q, MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE); break;
		case SILENT: break;
		case HANGUP: close(client); client = -1; break;
		case GARBAGE: {
			/* a reply to some other transaction: the id is not the query's */
			uint8_t r[11] = { q[0], (uint8_t)(q[1] ^ 0x5a), 0, 0, 0, 5, q[6], q[7], 2, 0x12, 0x34 };
			if (write(client, r, sizeof r) < 0)
				break;
			break;
		}
		}
	}
	if (client >= 0)
		close(client);
	return NULL;
}

/* Listen (on port 0 the first time: the kernel picks) and serve. */
static void server_start(int port)
{
	struct sockaddr_in a;
	socklen_t len = sizeof a;
	srv.ctx = modbus_new_tcp("127.0.0.1", port);
	assert_non_null(srv.ctx);
	srv.listen_fd = modbus_tcp_listen(srv.ctx, 1);
	assert_true(srv.listen_fd >= 0);
	assert_int_equal(getsockname(srv.listen_fd, (struct sockaddr *)&a, &len), 0);
	srv.port = ntohs(a.sin_port);
	atomic_store(&srv.stop, 0);
	assert_int_equal(pthread_create(&srv.th, NULL, serve, &srv), 0);
	srv.running = 1;
}

static void server_stop(void)
{
	if (!srv.running)
		return;
	srv.running = 0;
	atomic_store(&srv.stop, 1);
	pthread_join(srv.th, NULL);
	close(srv.listen_fd);
	modbus_free(srv.ctx);
}

static int setup(void **state)
{
	(void)state;
	memset(&srv, 0, sizeof srv);
	srv.map = modbus_mapping_new(32, 8, 100, 100);
	if (!srv.map)
		return -1;
	server_start(0);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	server_stop();
	modbus_mapping_free(srv.map);
	return 0;
}

/* Options from "key=value" strings, from line 1 of site.conf. */
struct optset {
	struct ps_test_opts t;
};

static const struct ps_opts *opts(struct optset *s, const char *const *kv)
{
	return ps_test_opts(&s->t, "site.conf", 1, kv);
}

static void open_dev(struct ps_dev *dev, const char *extra1, const char *extra2)
{
	struct optset s;
	char port[32];
	const char *kv[8] = { "host=127.0.0.1", port, "timeout=0.05", "backoff_min=1", "backoff_max=8",
	                      extra1, extra2, NULL };
	snprintf(port, sizeof port, "port=%d", srv.port);
	memset(dev, 0, sizeof *dev);
	dev->drv = &ps_driver_modbus;
	snprintf(dev->name, sizeof dev->name, "io1");
	if (ps_driver_modbus.open(dev, opts(&s, kv)) != 0)
		fail_msg("open: %s", dev->err);
}

static void add(struct ps_dev *dev, struct ps_point *pt, int role, const char *const *kv)
{
	struct optset s;
	memset(pt, 0, sizeof *pt);
	pt->role = role;
	snprintf(pt->name, sizeof pt->name, "%s", ps_role_name(role));
	if (ps_driver_modbus.add_point(dev, pt, opts(&s, kv)) != 0)
		fail_msg("add_point: %s", dev->err);
}

static void reads_writes_and_scales(void **state)
{
	static const char *const sensor[] = { "table=input_register", "address=0", NULL };
	static const char *const lux[] = { "table=holding_register", "address=7", "type=u32", NULL };
	static const char *const dim[] = { "table=holding_register", "address=10", "raw_max=4095", NULL };
	static const char *const relay[] = { "table=coil", "address=16", NULL };
	static const char *const in[] = { "table=discrete_input", "address=1", NULL };
	struct ps_dev dev;
	struct ps_point ps, pl, pd, pr, pi;
	double v;
	(void)state;
	open_dev(&dev, NULL, NULL);
	add(&dev, &ps, PS_ROLE_SENSOR, sensor);
	add(&dev, &pl, PS_ROLE_TASK_LUX, lux);
	add(&dev, &pd, PS_ROLE_DIM, dim);
	add(&dev, &pr, PS_ROLE_RELAY, relay);
	add(&dev, &pi, PS_ROLE_INPUT, in);
	srv.map->tab_input_registers[0] = 32768;
	srv.map->tab_registers[7] = 0x0002;
	srv.map->tab_registers[8] = 0x06f6;
	srv.map->tab_input_bits[1] = 1;
	assert_int_equal(ps_driver_modbus.read(&dev, &ps, 0, 0, &v), 0);
	assert_true(fabs(v - 32768 * 10.0 / 65535) < 1e-12);
	assert_int_equal(ps_driver_modbus.read(&dev, &pl, 0, 0, &v), 0);
	assert_true(v == 132854);
	assert_int_equal(ps_driver_modbus.read(&dev, &pi, 0, 0, &v), 0);
	assert_true(v == 1);
	assert_int_equal(ps_driver_modbus.write(&dev, &pd, 0, 0, 0.5), 0);
	assert_int_equal(srv.map->tab_registers[10], 2048);
	assert_int_equal(ps_driver_modbus.read(&dev, &pd, 0, 0, &v), 0);   /* read back */
	assert_true(fabs(v - 2048 / 4095.0) < 1e-12);
	assert_int_equal(ps_driver_modbus.write(&dev, &pr, 0, 0, 1), 0);
	assert_int_equal(srv.map->tab_bits[16], 1);
	/* an input cannot be written */
	assert_int_equal(ps_driver_modbus.write(&dev, &ps, 0, 0, 1), -1);
	assert_int_equal(errno, EINVAL);
	/* five points, one connection */
	assert_int_equal(atomic_load(&srv.accepted), 1);
	ps_driver_modbus.close(&dev);
}

static void exceptions_and_range_are_clear_faults(void **state)
{
	static const char *const far[] = { "table=input_register", "address=500", NULL };
	static const char *const twelve[] = { "table=input_register", "address=2", "raw_max=4095", NULL };
	static const char *const ok[] = { "table=input_register", "address=0", NULL };
	struct ps_dev dev;
	struct ps_point a, b, c;
	double v;
	int before;
	(void)state;
	open_dev(&dev, NULL, NULL);
	add(&dev, &a, PS_ROLE_SENSOR, far);
	add(&dev, &b, PS_ROLE_SENSOR, twelve);
	add(&dev, &c, PS_ROLE_SENSOR, ok);
	before = atomic_load(&srv.requests);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 0, 0, &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_string_equal(dev.err, "modbus io1 unit 1 IR 500: exception 2 (illegal data address)");
	/* an exception is an answer: not asked again */
	assert_int_equal(atomic_load(&srv.requests), before + 1);
	srv.map->tab_input_registers[2] = 0xffff;
	assert_int_equal(ps_driver_modbus.read(&dev, &b, 0, 0, &v), -1);
	assert_int_equal(errno, ERANGE);
	assert_string_equal(dev.err, "modbus io1 unit 1 IR 2: raw 65535 outside 0 to 4095");
	atomic_store(&srv.mode, EXCEPTION);
	assert_int_equal(ps_driver_modbus.read(&dev, &c, 0, 0, &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_string_equal(dev.err, "modbus io1 unit 1 IR 0: exception 4 (server device failure)");
	atomic_store(&srv.mode, NORMAL);
	assert_int_equal(ps_driver_modbus.read(&dev, &c, 0, 0, &v), 0);
	ps_driver_modbus.close(&dev);
}

static void silence_times_out_then_reconnects(void **state)
{
	static const char *const ok[] = { "table=input_register", "address=0", NULL };
	struct ps_dev dev;
	struct ps_point a;
	double v, t0, took;
	(void)state;
	open_dev(&dev, "retries=1", NULL);
	add(&dev, &a, PS_ROLE_SENSOR, ok);
	atomic_store(&srv.mode, SILENT);
	t0 = psd_time_mono();
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 0, 0, &v), -1);
	took = psd_time_mono() - t0;
	assert_int_equal(errno, ETIMEDOUT);
	assert_string_equal(dev.err, "modbus io1 unit 1 IR 0: no reply within 0.050 s");
	/* two tries of 50 ms: bounded, not a hang (a loose bound, not a benchmark) */
	assert_true(took >= 0.09 && took < 1.0);
	/* each timeout replaced the connection: a late reply cannot be taken for
	 * the next request's; the next read connects again at once */
	assert_int_equal(atomic_load(&srv.accepted), 2);
	atomic_store(&srv.mode, NORMAL);
	srv.map->tab_input_registers[0] = 65535;
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 0, 0, &v), 0);
	assert_true(v == 10);
	assert_int_equal(atomic_load(&srv.accepted), 3);
	ps_driver_modbus.close(&dev);
}

static void garbage_is_a_protocol_error(void **state)
{
	static const char *const ok[] = { "table=input_register", "address=0", NULL };
	struct ps_dev dev;
	struct ps_point a;
	double v;
	(void)state;
	open_dev(&dev, "retries=0", NULL);
	add(&dev, &a, PS_ROLE_SENSOR, ok);
	atomic_store(&srv.mode, GARBAGE);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 0, 0, &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(dev.err, "modbus io1 unit 1 IR 0: garbled reply"));
	atomic_store(&srv.mode, NORMAL);
	srv.map->tab_input_registers[0] = 0;
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 1, 1, &v), 0);
	assert_true(v == 0);
	ps_driver_modbus.close(&dev);
}

static void lost_device_backs_off_on_the_callers_clock(void **state)
{
	static const char *const ok[] = { "table=input_register", "address=0", NULL };
	struct ps_dev dev;
	struct ps_point a;
	double v;
	int port = srv.port, before;
	(void)state;
	open_dev(&dev, "retries=0", NULL);   /* backoff 1 s doubling to 8 s */
	add(&dev, &a, PS_ROLE_SENSOR, ok);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 100, 100, &v), 0);
	/* the module hangs up, then goes away */
	atomic_store(&srv.mode, HANGUP);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 100, 100, &v), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(dev.err, "modbus io1 unit 1 IR 0: connection lost"));
	server_stop();
	atomic_store(&srv.mode, NORMAL);
	before = atomic_load(&srv.accepted);
	/* before the backoff has passed: no attempt at all */
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 100.5, 100.5, &v), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(dev.err, "not connected"));
	assert_non_null(strstr(dev.err, "next attempt in 0.5 s"));
	/* at 101 it tries, is refused, and waits 2 s; then 4 s; then 8 s (the cap) */
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 101, 101, &v), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(dev.err, "cannot connect"));
	assert_non_null(strstr(dev.err, "next attempt in 2.0 s"));
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 102.9, 102.9, &v), -1);
	assert_non_null(strstr(dev.err, "not connected"));
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 103, 103, &v), -1);
	assert_non_null(strstr(dev.err, "next attempt in 4.0 s"));
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 107, 107, &v), -1);
	assert_non_null(strstr(dev.err, "next attempt in 8.0 s"));
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 115, 115, &v), -1);
	assert_non_null(strstr(dev.err, "next attempt in 8.0 s"));
	/* the module is back; the driver finds it at the next due attempt */
	server_start(port);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 120, 120, &v), -1);
	assert_non_null(strstr(dev.err, "not connected"));
	srv.map->tab_input_registers[0] = 13107;
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 123, 123, &v), 0);
	assert_true(fabs(v - 2) < 1e-12);
	assert_int_equal(atomic_load(&srv.accepted), before + 1);
	ps_driver_modbus.close(&dev);
}

struct events {
	int n;
	double last;
};

static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	struct events *e = user;
	(void)dev;
	(void)pt;
	(void)now;
	e->n++;
	e->last = value;
}

static void polled_points_and_input_events(void **state)
{
	static const char *const in[] = { "table=discrete_input", "address=0", "period=1", NULL };
	static const char *const sensor[] = { "table=input_register", "address=3", "period=2", NULL };
	struct ps_dev dev;
	struct ps_point pi, ps;
	struct events ev = { 0, -1 };
	double v;
	(void)state;
	open_dev(&dev, NULL, NULL);
	dev.on_event = on_event;
	dev.event_user = &ev;
	add(&dev, &pi, PS_ROLE_INPUT, in);
	add(&dev, &ps, PS_ROLE_SENSOR, sensor);
	assert_true(ps_driver_modbus.deadline(&dev, &(double){ INFINITY }) <= 0);   /* due at once */
	srv.map->tab_input_registers[3] = 65535;
	assert_int_equal(ps_driver_modbus.service(&dev, 10, 10), 0);
	assert_int_equal(ev.n, 1);   /* the first poll reports the state */
	assert_true(ev.last == 0);
	assert_true(ps_driver_modbus.deadline(&dev, &(double){ INFINITY }) == 11);
	srv.map->tab_input_bits[0] = 1;
	srv.map->tab_input_registers[3] = 0;
	assert_int_equal(ps_driver_modbus.service(&dev, 11, 11), 0);
	assert_int_equal(ev.n, 2);
	assert_true(ev.last == 1);
	/* the sensor was polled at 10 (10 V): read answers from that poll while
	 * it is not older than its period, although the module now says 0 V */
	assert_int_equal(ps_driver_modbus.read(&dev, &ps, 11.5, 11.5, &v), 0);
	assert_true(v == 10);
	assert_int_equal(ps_driver_modbus.service(&dev, 12, 12), 0);   /* no change, no event */
	assert_int_equal(ev.n, 2);
	assert_int_equal(ps_driver_modbus.read(&dev, &ps, 12.5, 12.5, &v), 0);
	assert_true(v == 0);
	/* with no service for longer than the period, read asks the module */
	srv.map->tab_input_registers[3] = 13107;
	assert_int_equal(ps_driver_modbus.read(&dev, &ps, 14.5, 14.5, &v), 0);
	assert_true(fabs(v - 2) < 1e-12);
	ps_driver_modbus.close(&dev);
}

static void bad_device_options(void **state)
{
	struct ps_dev dev;
	struct optset s;
	static const char *const none[] = { "unit=1", NULL };
	static const char *const both[] = { "host=127.0.0.1", "device=/dev/ttyS0", NULL };
	static const char *const baud[] = { "device=/dev/null", "baud=12345", NULL };
	static const char *const unit[] = { "device=/dev/null", "unit=0", NULL };
	static const char *const parity[] = { "device=/dev/null", "parity=mark", NULL };
	(void)state;
	memset(&dev, 0, sizeof dev);
	snprintf(dev.name, sizeof dev.name, "io1");
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, none)), -1);
	assert_int_equal(errno, EINVAL);
	assert_string_equal(dev.err, "site.conf:0: a modbus device needs either host (TCP) or device (RTU)");
	ps_driver_modbus.close(&dev);
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, both)), -1);
	assert_non_null(strstr(dev.err, "site.conf:2: a modbus device needs either"));
	ps_driver_modbus.close(&dev);
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, baud)), -1);
	assert_string_equal(dev.err, "site.conf:2: baud: '12345' is not one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400");
	ps_driver_modbus.close(&dev);
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, unit)), -1);
	assert_string_equal(dev.err, "site.conf:2: unit: RTU units are 1 to 247");
	ps_driver_modbus.close(&dev);
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, parity)), -1);
	assert_string_equal(dev.err, "site.conf:2: parity: 'mark' is not one of none, even, odd");
	ps_driver_modbus.close(&dev);
}

static void rtu_device_absent_is_enodev(void **state)
{
	static const char *const kv[] = { "device=/nonexistent/ttyUSB9", "backoff_min=5", NULL };
	static const char *const ok[] = { "table=input_register", "address=0", NULL };
	struct ps_dev dev;
	struct ps_point a;
	struct optset s;
	double v;
	(void)state;
	memset(&dev, 0, sizeof dev);
	snprintf(dev.name, sizeof dev.name, "meter");
	assert_int_equal(ps_driver_modbus.open(&dev, opts(&s, kv)), 0);   /* may be plugged in later */
	add(&dev, &a, PS_ROLE_TASK_LUX, ok);
	assert_int_equal(ps_driver_modbus.read(&dev, &a, 0, 0, &v), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(dev.err, "modbus meter (/nonexistent/ttyUSB9): cannot connect"));
	assert_non_null(strstr(dev.err, "next attempt in 5.0 s"));
	ps_driver_modbus.close(&dev);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(reads_writes_and_scales, setup, teardown),
		cmocka_unit_test_setup_teardown(exceptions_and_range_are_clear_faults, setup, teardown),
		cmocka_unit_test_setup_teardown(silence_times_out_then_reconnects, setup, teardown),
		cmocka_unit_test_setup_teardown(garbage_is_a_protocol_error, setup, teardown),
		cmocka_unit_test_setup_teardown(lost_device_backs_off_on_the_callers_clock, setup, teardown),
		cmocka_unit_test_setup_teardown(polled_points_and_input_events, setup, teardown),
		cmocka_unit_test(bad_device_options),
		cmocka_unit_test(rtu_device_absent_is_enodev),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
#else
int main(void)
{
	printf("the modbus driver is not compiled in (WITH_MODBUS)\n");
	return 77;
}
#endif
