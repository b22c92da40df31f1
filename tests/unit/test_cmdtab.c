/* SPDX-License-Identifier: ISC */
/* The command table (daemon/cmdtab.c): every row complete; the socket's
 * help lists exactly the table's rows; each front end accepts exactly the
 * commands the table grants it (the socket, the web console, MQTT's two
 * scopes); the typed arguments refused with the socket's messages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include <json-c/json.h>

#include "cmdtab.h"
#include "ctlcmd.h"
#include "ctlsock.h"
#include "loop.h"
#include "mqttcmd.h"
#include "mqttconf.h"
#include "webreq.h"

static void test_rows_complete(void **state)
{
	size_t n;
	const struct psd_cmdtab *t = psd_cmdtab_rows(&n);
	(void)state;
	assert_true(n > 0);
	for (size_t i = 0; i < n; i++) {
		size_t w = strlen(t[i].word);
		int last = 0;
		if (!t[i].help || !t[i].fn || !t[i].fronts)
			fail_msg("row %s lacks its help, handler or front ends", t[i].word);
		/* help's entry begins with the command's own word */
		if (strncmp(t[i].help, t[i].word, w) != 0 || (t[i].help[w] != 0 && t[i].help[w] != ' '))
			fail_msg("row %s: help '%s' is another command's", t[i].word, t[i].help);
		assert_ptr_equal(psd_cmdtab_find(t[i].word), &t[i]);
		/* an optional zone or the free words end the list */
		for (int k = 0; k < PSD_CMDTAB_MAX_ARGS; k++) {
			if (last && t[i].arg[k] != PSD_CMDTAB_END)
				fail_msg("row %s: argument %d after an optional one", t[i].word, k + 1);
			last = t[i].arg[k] == PSD_CMDTAB_ZONE_OPT || t[i].arg[k] == PSD_CMDTAB_WORDS ||
			       t[i].arg[k] == PSD_CMDTAB_END;
		}
		/* MQTT's commands = all allows what commands = override does */
		if ((t[i].fronts & PSD_CMDTAB_MQTT_OVERRIDE) && !(t[i].fronts & PSD_CMDTAB_MQTT_ALL))
			fail_msg("row %s: MQTT override but not all", t[i].word);
		if ((t[i].fronts & (PSD_CMDTAB_MQTT_OVERRIDE | PSD_CMDTAB_MQTT_ALL)) && !t[i].mqtt_verbs)
			fail_msg("row %s: granted MQTT without a verb", t[i].word);
		/* BACnet writes: it reaches only commands that change state */
		if ((t[i].fronts & PSD_CMDTAB_BACNET) && !t[i].changes)
			fail_msg("row %s: BACnet reaches a read-only command", t[i].word);
	}
	for (size_t i = 0; i < n; i++)
		for (size_t k = i + 1; k < n; k++)
			if (strcmp(t[i].word, t[k].word) == 0)
				fail_msg("command %s has two rows", t[i].word);
}

/* The socket's help, asked as a client would: its " | "-separated
 * entries are the socket's rows, each once, in the table's order. */
static void test_help_lists_rows(void **state)
{
	static struct psd_daemon d;   /* help reads nothing of the daemon */
	struct psd_ctl_reply r = { 0 };
	char line[] = "help", *list, *next;
	json_object *o, *v;
	size_t n, row = 0;
	const struct psd_cmdtab *t = psd_cmdtab_rows(&n);
	(void)state;
	psd_cmdtab_request(&d, line, &r);
	assert_non_null(o = json_tokener_parse(r.text));
	assert_true(json_object_object_get_ex(o, "ok", &v) && json_object_get_boolean(v));
	assert_true(json_object_object_get_ex(o, "commands", &v));
	assert_non_null(list = strdup(json_object_get_string(v)));
	for (char *e = list; e; e = next) {
		char *sep = strstr(e, " | ");
		next = sep ? sep + 3 : NULL;
		if (sep)
			*sep = 0;
		while (row < n && !(t[row].fronts & PSD_CMDTAB_SOCKET))
			row++;
		if (row >= n)
			fail_msg("help lists '%s', which the table has no socket row for", e);
		assert_string_equal(e, t[row].help);
		row++;
	}
	while (row < n && !(t[row].fronts & PSD_CMDTAB_SOCKET))
		row++;
	if (row < n)
		fail_msg("help does not list %s", t[row].word);
	free(list);
	json_object_put(o);
	psd_ctlsock_reply_free(&r);
}

/* An MQTT verb a scope does not grant: set/<verb> above [mqtt] commands. */
static int mqtt_takes(const char *verb, int commands)
{
	return psd_mqttcmd_scope(psd_cmdtab_verb_fronts(verb)) <= commands;
}

/* Each front end's own check, against the table's bits. */
static void test_fronts_refuse_what_is_not_granted(void **state)
{
	size_t n;
	const struct psd_cmdtab *t = psd_cmdtab_rows(&n);
	char err[256];
	(void)state;
	for (size_t i = 0; i < n; i++) {
		char line[64];
		int console = (t[i].fronts & PSD_CMDTAB_CONSOLE) != 0;
		snprintf(line, sizeof line, "%s office", t[i].word);
		if ((psd_webreq_line_ok(line, err, sizeof err) == 0) != console)
			fail_msg("the console %s '%s'", console ? "refuses" : "accepts", line);
		for (size_t k = 0; t[i].mqtt_verbs && t[i].mqtt_verbs[k]; k++) {
			const char *v = t[i].mqtt_verbs[k];
			assert_int_equal(mqtt_takes(v, PSD_MQTT_COMMANDS_OVERRIDE),
			                 (t[i].fronts & PSD_CMDTAB_MQTT_OVERRIDE) != 0);
			assert_int_equal(mqtt_takes(v, PSD_MQTT_COMMANDS_ALL), (t[i].fronts & PSD_CMDTAB_MQTT_ALL) != 0);
			assert_false(mqtt_takes(v, PSD_MQTT_COMMANDS_NONE));
		}
		if (!(t[i].fronts & (PSD_CMDTAB_MQTT_OVERRIDE | PSD_CMDTAB_MQTT_ALL))) {
			/* a socket word MQTT is not granted is no set/ command there */
			struct psd_mqtt_cmd cmd;
			const struct psd_cmdtab *via = psd_cmdtab_find_verb(t[i].word);
			assert_true(via == NULL || via != &t[i]);
			if (!via)
				assert_int_equal(psd_mqttcmd_parse("lab", "office", t[i].word, "", 0, 3600, &cmd, err,
				                                   sizeof err),
				                 -1);
		}
	}
	/* a word the table does not have: refused by every front end */
	{   /* the socket's own answer */
		static struct psd_daemon d;
		struct psd_ctl_reply r = { 0 };
		char line[] = "statusx office";
		psd_cmdtab_request(&d, line, &r);
		assert_string_equal(r.text, "{\"ok\":false,\"error\":\"unknown request 'statusx' or wrong arguments; try help\"}");
		psd_ctlsock_reply_free(&r);
	}
	assert_int_equal(psd_webreq_line_ok("statusx", err, sizeof err), -1);
	assert_int_equal(psd_mqttcmd_scope(psd_cmdtab_verb_fronts("statusx")), PSD_MQTT_COMMANDS_NONE);
	assert_int_equal(psd_cmdtab_allows("statusx", PSD_CMDTAB_SOCKET | PSD_CMDTAB_CONSOLE | PSD_CMDTAB_BACNET), 0);
}

static struct psd_engine engine;   /* no zones: every zone is unknown */

static int parse(const char *text, struct psd_cmdtab_args *a, char *err, size_t errlen)
{
	char line[128], *argv[8];
	int argc = 0;
	snprintf(line, sizeof line, "%s", text);
	for (char *save = NULL, *w = strtok_r(line, " ", &save); w && argc < 8; w = strtok_r(NULL, " ", &save))
		argv[argc++] = w;
	return psd_cmdtab_parse(psd_cmdtab_find(argv[0]), &engine, argc, argv, a, err, errlen);
}

static void refused(const char *text, const char *why)
{
	struct psd_cmdtab_args a;
	char err[256] = "";
	assert_int_equal(parse(text, &a, err, sizeof err), -1);
	if (strcmp(err, why) != 0)
		fail_msg("'%s': error '%s', not '%s'", text, err, why);
}

/* The words' count and types before the zone: the usage for a malformed
 * request whatever its zone, "no zone" only for a well-formed one. */
static void test_typed_arguments(void **state)
{
	struct psd_cmdtab_args a;
	char err[256];
	(void)state;
	refused("override office 0.5", "usage: override ZONE LEVEL SECONDS (level 0 to 1)");
	refused("override office half 60", "usage: override ZONE LEVEL SECONDS (level 0 to 1)");
	refused("override office 0.5 inf", "usage: override ZONE LEVEL SECONDS (level 0 to 1)");
	refused("override office 0.5 60", "no zone 'office'");
	refused("target office", "usage: target ZONE LUX");
	refused("target office 500 1", "usage: target ZONE LUX");
	refused("status office hall", "usage: status [ZONE]");
	refused("status office", "no zone 'office'");
	refused("ping now", "unknown request 'ping' or wrong arguments; try help");
	refused("ratios a b", "unknown request 'ratios' or wrong arguments; try help");
	refused("off", "usage: off ZONE");
	assert_int_equal(parse("status", &a, err, sizeof err), 0);
	assert_null(a.zone);
	assert_int_equal(parse("help me please", &a, err, sizeof err), 0);
	assert_int_equal(a.argc, 3);
	/* the typed entry names the zone as the socket does */
	assert_int_equal(psd_cmdtab_release(&engine, "hall", err, sizeof err), -1);
	assert_string_equal(err, "no zone 'hall'");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rows_complete),
		cmocka_unit_test(test_help_lists_rows),
		cmocka_unit_test(test_fronts_refuse_what_is_not_granted),
		cmocka_unit_test(test_typed_arguments),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
