/* SPDX-License-Identifier: ISC */
/* MQTT's pieces that need no broker: the [mqtt] section (every error with
 * its file:line), the state JSON of a logged sample, the Home Assistant
 * discovery messages, and the database's cursor and announced zones. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>

#include "cmdtab.h"
#include "config.h"
#include "db.h"
#include "mqttcmd.h"
#include "mqttmsg.h"
#include "points.h"

static struct psd_config cf;
static const char base[] = "[psensd]\nresults = r\ndatabase = d.db\n[device io]\ndriver = loopback\n"
                           "[zone a]\ndevice = io\n";

static int has_error(const char *text)
{
	for (size_t i = 0; i < cf.conf.nerrors; i++)
		if (strstr(cf.conf.errors[i], text))
			return 1;
	return 0;
}

static int load(const char *mqtt)
{
	char text[2048];
	snprintf(text, sizeof text, "%s%s", base, mqtt);
	return psd_config_load_string(&cf, text, "t.conf");
}

static void conf_section(void **state)
{
	(void)state;
	/* no [mqtt]: nothing to open */
	assert_int_equal(load(""), 0);
	assert_int_equal(cf.mqtt.enabled, 0);
	psd_config_free(&cf);
	assert_int_equal(load("[mqtt]\nhost = 10.0.0.5\nsite = b1\nrate = 50\n"), 0);
	assert_int_equal(cf.mqtt.enabled, 1);
	assert_string_equal(cf.mqtt.host, "10.0.0.5");
	assert_int_equal(cf.mqtt.port, 1883);
	assert_string_equal(cf.mqtt.site, "b1");
	assert_true(cf.mqtt.rate == 50);
	assert_int_equal(cf.mqtt.keepalive, 30);
	assert_int_equal(cf.mqtt.discovery, 1);
	assert_string_equal(cf.mqtt.discovery_prefix, "homeassistant");
	psd_config_free(&cf);
	/* lines 8.. are the [mqtt] section's */
	assert_int_equal(load("[mqtt]\nport = 99999\nsite = a b\nkeyfile = /etc/hostname\nrate = 0\nhots = x\n"), -1);
	assert_true(has_error("t.conf:8: [mqtt] needs 'host'"));
	assert_true(has_error("t.conf:9: port"));
	assert_true(has_error("t.conf:10: site: 'a b' is not"));
	assert_true(has_error("t.conf:8: [mqtt]: certfile and keyfile go together"));
	assert_true(has_error("t.conf:12: rate"));
	assert_true(has_error("t.conf:13:"));   /* the typo */
	psd_config_free(&cf);
	assert_int_equal(psd_config_load_string(&cf, "[psensd]\nresults = r\n[device io]\ndriver = loopback\n"
	                                         "[zone a]\ndevice = io\n[mqtt]\nhost = h\n", "t.conf"), -1);
	assert_true(has_error("t.conf:7: [mqtt] publishes the sample log: set database"));
	psd_config_free(&cf);
}

static void conf_password(void **state)
{
	char dir[] = "/tmp/psmqttXXXXXX", path[64], text[256];
	FILE *fp;
	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof path, "%s/pw", dir);
	fp = fopen(path, "w");
	fputs("s3cret\nsecond line\n", fp);
	fclose(fp);
	chmod(path, 0600);
	snprintf(text, sizeof text, "[mqtt]\nhost = h\nuser = u\npassword_file = %s\n", path);
	assert_int_equal(load(text), 0);
	assert_string_equal(cf.mqtt.password, "s3cret");
	psd_config_free(&cf);
	chmod(path, 0620);
	assert_int_equal(load(text), -1);
	assert_true(has_error("t.conf:11: password_file:"));
	assert_true(has_error("is writable by its group (mode 0620)"));
	psd_config_free(&cf);
	chmod(path, 0606);
	assert_int_equal(load(text), -1);
	assert_true(has_error("is writable by everyone"));
	psd_config_free(&cf);
	chmod(path, 0604);
	assert_int_equal(load(text), -1);
	assert_true(has_error("is readable by everyone (mode 0604)"));
	psd_config_free(&cf);
	chmod(path, 0640);
	assert_int_equal(load(text), 0);
	psd_config_free(&cf);
	unlink(path);
	assert_int_equal(load(text), -1);
	assert_true(has_error("No such file"));
	psd_config_free(&cf);
	rmdir(dir);
}

/* commands: none unless the file says otherwise, one of three words */
static void conf_commands(void **state)
{
	(void)state;
	assert_int_equal(load("[mqtt]\nhost = h\n"), 0);
	assert_int_equal(cf.mqtt.commands, PSD_MQTT_COMMANDS_NONE);
	psd_config_free(&cf);
	assert_int_equal(load("[mqtt]\nhost = h\ncommands = override\n"), 0);
	assert_int_equal(cf.mqtt.commands, PSD_MQTT_COMMANDS_OVERRIDE);
	psd_config_free(&cf);
	assert_int_equal(load("[mqtt]\nhost = h\ncommands = all\n"), 0);
	assert_int_equal(cf.mqtt.commands, PSD_MQTT_COMMANDS_ALL);
	psd_config_free(&cf);
	assert_int_equal(load("[mqtt]\nhost = h\ncommands = yes\n"), -1);
	assert_true(has_error("t.conf:10: commands"));
	psd_config_free(&cf);
	/* the scope each verb needs */
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("override")), PSD_MQTT_COMMANDS_OVERRIDE);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("release")), PSD_MQTT_COMMANDS_OVERRIDE);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("status")), PSD_MQTT_COMMANDS_OVERRIDE);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("target")), PSD_MQTT_COMMANDS_ALL);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("calibrate")), PSD_MQTT_COMMANDS_ALL);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("accept")), PSD_MQTT_COMMANDS_ALL);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("reboot")), PSD_MQTT_COMMANDS_NONE);
}

static void state_json(void **state)
{
	char buf[2048];
	struct psd_sample s = { 30000, 30000, 2.5, 0.25, 410, NAN, 1.2, 300, "daylight_mean", 250, NULL, "a", NAN, NULL, -1, NAN };
	json_object *o, *v;
	(void)state;
	assert_true(psd_mqttmsg_state_json(buf, sizeof buf, "b1", 77, 1700000000.25, &s, NULL, NULL) > 0);
	assert_non_null(o = json_tokener_parse(buf));
	assert_true(json_object_object_get_ex(o, "id", &v));
	assert_int_equal(json_object_get_int64(v), 77);
	assert_true(json_object_object_get_ex(o, "utc", &v));
	assert_string_equal(json_object_get_string(v), "2023-11-14T22:13:20.250Z");
	assert_true(json_object_object_get_ex(o, "task_lux", &v));
	assert_null(v);     /* NAN: null */
	assert_true(json_object_object_get_ex(o, "level", &v));
	assert_true(json_object_get_double(v) == 0.25);
	assert_true(json_object_object_get_ex(o, "est_task_lux", &v));
	assert_true(json_object_get_double(v) == 410);
	assert_true(json_object_object_get_ex(o, "fault", &v));
	assert_null(v);
	json_object_put(o);
	s.fault = "sensor: stale";
	assert_int_equal(psd_mqttmsg_state_json(buf, 20, "b1", 77, 0, &s, NULL, NULL), -1);   /* does not fit */
	assert_true(psd_mqttmsg_state_json(buf, sizeof buf, "b1", 78, 0, &s, NULL, NULL) > 0);
	assert_non_null(strstr(buf, "\"fault\":\"sensor: stale\""));
	assert_null(strstr(buf, "\"points\""));   /* none given: none published */
	{   /* the point model's object, as given, under "points" */
		json_object *pts = json_object_new_object();
		json_object_object_add(pts, "level", json_object_new_double(42.5));
		json_object_object_add(pts, "state", json_object_new_string("override"));
		assert_true(psd_mqttmsg_state_json(buf, sizeof buf, "b1", 79, 0, &s, NULL, pts) > 0);
		assert_non_null(strstr(buf, "\"points\":{\"level\":42.5,\"state\":\"override\"}"));
	}
}

/* The zone of the discovery test has every point but the task meter's lux. */
static int has_but_task_lux(void *user, size_t i)
{
	(void)user;
	return i != (size_t)psd_points_find("task_lux");
}

static void discovery(void **state)
{
	char topic[256], payload[2048];
	json_object *o;
	int k, n = 0, empty = 0, pt;
	(void)state;
	for (k = 0; psd_mqttmsg_discovery(k, "homeassistant", "b.1", "a", has_but_task_lux, NULL, 1, topic,
	                               sizeof topic, payload, sizeof payload, &pt) == 0; k++) {
		assert_int_equal(strncmp(topic, "homeassistant/", 14), 0);
		assert_non_null(strstr(topic, "/psensd_b_1_a/"));   /* '.' is not in an HA node id */
		if (!payload[0]) {
			empty++;
			assert_non_null(strstr(topic, "/task_lux/"));   /* no task meter: removed */
			continue;
		}
		n++;
		o = json_tokener_parse(payload);
		assert_non_null(o);
		json_object_put(o);
		assert_non_null(strstr(payload, "\"availability_topic\":\"psensd/b.1/status\""));
		assert_non_null(strstr(payload, "\"state_topic\":\"psensd/b.1/a/state\""));
	}
	/* one entity per point of the point model, and the override's number */
	assert_int_equal(k, (int)psd_points_count() + 1);
	assert_int_equal(n, k - 1);
	assert_int_equal(empty, 1);
	/* the entities that predate the point model keep their topics */
	assert_int_equal(psd_mqttmsg_discovery(0, "ha", "s", "z", has_but_task_lux, NULL, 1, topic, sizeof topic, payload,
	                                    sizeof payload, &pt), 0);
	assert_string_equal(topic, "ha/sensor/psensd_s_z/est_task_lux/config");
	assert_int_equal(psd_mqttmsg_discovery(5, "ha", "s", "z", has_but_task_lux, NULL, 1, topic, sizeof topic, payload,
	                                    sizeof payload, &pt), 0);
	assert_string_equal(topic, "ha/number/psensd_s_z/override/config");
	assert_int_equal(pt, -1);
	assert_non_null(strstr(payload, "\"command_topic\":\"psensd/s/z/set/override\""));
	/* without commands over MQTT the override entity is removed (an empty config) */
	assert_int_equal(psd_mqttmsg_discovery(5, "ha", "s", "z", has_but_task_lux, NULL, 0, topic, sizeof topic, payload,
	                                    sizeof payload, &pt), 0);
	assert_string_equal(topic, "ha/number/psensd_s_z/override/config");
	assert_string_equal(payload, "");
}

static long long ids[16];
static int nids;
static void collect(void *user, long long id, double utc, const struct psd_sample *s)
{
	(void)user;
	(void)s;
	assert_true(utc > 1.6e9);   /* the wall clock at logging */
	ids[nids++] = id;
}

static char names[4][48];
static int nnames;
static void name(void *user, const char *n)
{
	(void)user;
	snprintf(names[nnames++], sizeof names[0], "%s", n);
}

static void db_cursor(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_sample s = { 0, 0, 1, 0.5, 100, NAN, 0, 0, NULL, 1, NULL, "a", NAN, NULL, -1, NAN };
	(void)state;
	assert_non_null(db);
	psd_db_set_batch(db, 1);
	assert_int_equal(psd_db_mqtt_cursor(db, "b1"), 0);
	for (int i = 0; i < 5; i++) {
		s.t = i;
		assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	}
	assert_int_equal(psd_db_last_id(db), 5);
	nids = 0;
	assert_int_equal(psd_db_samples_after(db, 1, 3, collect, NULL, err, sizeof err), 3);
	assert_int_equal(nids, 3);
	assert_true(ids[0] == 2 && ids[1] == 3 && ids[2] == 4);
	assert_int_equal(psd_db_samples_after(db, 4, 10, collect, NULL, err, sizeof err), 1);
	assert_int_equal(psd_db_mqtt_set_cursor(db, "b1", 4, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_set_cursor(db, "b2", 2, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_cursor(db, "b1"), 4);
	assert_int_equal(psd_db_mqtt_cursor(db, "b2"), 2);
	assert_int_equal(psd_db_mqtt_announce(db, "b1", "a", 1, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_announce(db, "b1", "a", 1, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_announce(db, "b1", "c", 1, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_announce(db, "b2", "x", 1, err, sizeof err), 0);
	assert_int_equal(psd_db_mqtt_announce(db, "b1", "a", 0, err, sizeof err), 0);
	nnames = 0;
	assert_int_equal(psd_db_mqtt_announced(db, "b1", name, NULL), 0);
	assert_int_equal(nnames, 1);
	assert_string_equal(names[0], "c");
	psd_db_close(db);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(conf_section),
		cmocka_unit_test(conf_password),
		cmocka_unit_test(conf_commands),
		cmocka_unit_test(state_json),
		cmocka_unit_test(discovery),
		cmocka_unit_test(db_cursor),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
