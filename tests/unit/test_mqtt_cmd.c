/* SPDX-License-Identifier: ISC */
/* MQTT command payloads (daemon/mqtt/mqttcmd.c): each set/<verb> payload becomes
 * the control-socket request that does the same, or is refused with a
 * reason; nothing a payload holds reaches the request line unchecked. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "mqttcmd.h"

static struct psd_mqtt_cmd cmd;
static char err[512];

static int parse(const char *zone, const char *verb, const char *payload)
{
	err[0] = 0;
	return psd_mqttcmd_parse("lab", zone, verb, payload, strlen(payload), 3600, &cmd, err, sizeof err);
}

static void good(const char *verb, const char *payload, const char *line)
{
	if (parse("office", verb, payload) != 0)
		fail_msg("set/%s '%s' refused: %s", verb, payload, err);
	assert_string_equal(cmd.line, line);
}

static void bad(const char *zone, const char *verb, const char *payload, const char *why)
{
	assert_int_equal(parse(zone, verb, payload), -1);
	if (!strstr(err, why))
		fail_msg("set/%s '%s': error '%s' lacks '%s'", verb, payload, err, why);
}

static void test_numbers(void **state)
{
	(void)state;
	good("target", "300", "target office 300");
	good("target", "{\"lux\": 412.5}", "target office 412.5");
	good("target", " 7 ", "target office 7");
	good("override", "0.25", "override office 0.25 3600");
	good("override", "{\"level\":0.3,\"seconds\":600}", "override office 0.29999999999999999 600");
	good("lux", "{\"lux\": 401}", "calibrate office lux 401");
	/* the range is the request's business (psd_engine_set_target), not the payload's */
	good("target", "-5", "target office -5");
}

static void test_words(void **state)
{
	(void)state;
	good("calibrate", "night", "calibrate office night");
	good("calibrate", "\"finish\"", "calibrate office finish");
	good("calibrate", "{\"step\":\"day\",\"level\":0.6}", "calibrate office day 0.59999999999999998");
	good("calibrate", "{\"step\":\"lux\",\"lux\":380}", "calibrate office lux 380");
	good("accept", "", "calibrate office accept");
	good("accept", "{}", "calibrate office accept");
	good("release", "", "release office");
	good("status", "{\"id\":\"q1\"}", "status office");
	assert_string_equal(cmd.id, "q1");
	good("target", "{\"lux\":300,\"id\":42,\"site\":\"lab\"}", "target office 300");
	assert_string_equal(cmd.id, "42");
}

static void test_refused(void **state)
{
	(void)state;
	bad("office", "target", "", "needs a number");
	bad("office", "target", "abc", "needs a number");
	bad("office", "target", "\"abc\"", "needs a number");
	bad("office", "target", "{\"lux\":\"300\"}", "\"lux\" is not a finite number");
	bad("office", "target", "{\"lux\":true}", "not a finite number");
	bad("office", "target", "[300]", "not array");
	bad("office", "target", "1e999", "finite");
	bad("office", "target", "NaN", "finite");
	bad("office", "target", "{\"lux\":300,\"extra\":1}", "unknown field \"extra\"");
	bad("office", "target", "{\"lux\":300", "not JSON");
	bad("office", "target", "300 400", "not JSON");
	bad("office", "override", "{\"seconds\":60}", "needs \"level\"");
	bad("office", "override", "{\"level\":0.5,\"seconds\":\"x\"}", "\"seconds\" is not");
	bad("office", "calibrate", "dusk", "no step 'dusk'");
	bad("office", "calibrate", "5", "needs a step");
	bad("office", "calibrate", "{\"step\":\"night\",\"level\":0.5}", "belongs to the day step");
	bad("office", "calibrate", "{\"step\":\"lux\"}", "needs \"lux\"");
	bad("office", "accept", "1", "takes no value");
	bad("office", "release", "{\"level\":1}", "unknown field");
	bad("office", "reboot", "", "no command set/reboot");
	bad("office", "target", "{\"lux\":1,\"site\":\"other\"}", "command for site 'other' refused");
	bad("office", "target", "{\"lux\":1,\"id\":[1]}", "\"id\" is not");
	bad("office", "target", "{\"lux\":1,\"id\":\"a\\u0001b\"}", "control character");
}

/* a zone name goes into a request line: no spaces, no second word */
static void test_zone_and_size(void **state)
{
	char big[PSD_MQTT_MAX_PAYLOAD + 2];
	(void)state;
	bad("office release", "target", "300", "is not a zone name");
	bad("", "target", "300", "is not a zone name");
	bad("a/b", "target", "300", "is not a zone name");
	memset(big, ' ', sizeof big - 1);
	big[sizeof big - 1] = 0;
	big[0] = '1';
	bad("office", "target", big, "at most 512");
	big[PSD_MQTT_MAX_PAYLOAD] = 0;   /* 512 bytes: taken */
	good("target", big, "target office 1");
	assert_int_equal(psd_mqttcmd_parse("lab", "office", "target", "3\0" "00", 4, 60, &cmd, err, sizeof err), -1);
	assert_non_null(strstr(err, "NUL"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_numbers),
		cmocka_unit_test(test_words),
		cmocka_unit_test(test_refused),
		cmocka_unit_test(test_zone_and_size),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
