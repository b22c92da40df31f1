/* SPDX-License-Identifier: ISC */
#include "mqtt.h"

#include <errno.h>
#include <json-c/json.h>
#include <math.h>
#include <mosquitto.h>
#include <mqtt_protocol.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "config.h"
#include "engine.h"
#include "errbuf.h"
#include "json.h"
#include "log.h"
#include "mqttcmd.h"
#include "mqttconf.h"
#include "mqttmsg.h"
#include "points.h"
#include "time.h"

enum { BATCH = 64, MSG = 4096, TOPIC = 256, MAX_SEEN = 2 * PSD_MAX_ZONES };
static const double RETRY_MIN = 0.5, RETRY_MAX = 5;   /* s between connection attempts */
static const double CURSOR_EVERY = 1;                 /* s between saves of the cursor */

struct slot {
	int mid;
	long long id;             /* the sample the message carries */
	int acked;
};

/* What the last published sample of a zone said, and its live state, to
 * publish the changes as events. */
struct seen {
	char zone[PSD_MQTT_NAME];
	char fault[160];
	int faulted;              /* as of the last sample published (0 at a start) */
	int have_live, cal_state, drift;
};

/* The client's counters, status -j's "mqtt". */
struct stats {
	int connected;
	long long cursor;            /* last sample id acknowledged */
	long long sent;              /* last sample id published */
	unsigned long published, acked, commands, refused, connects;
	double turn_max;             /* the longest mqtt_service, wall seconds */
	double turn_cpu_max;         /* the most CPU time one took (the rest: waiting for the CPU) */
};

struct psd_mqtt {
	struct mosquitto *mosq;
	struct psd_engine *e;
	const struct psd_points *pts; /* the point model's state: the state's "points" */
	psd_frontend_fixed_fn fn;
	psd_frontend_grants_fn grants;
	void *user;
	char site[PSD_MQTT_NAME], prefix[64], status_topic[TOPIC];
	double rate;
	long inflight;
	int discovery;
	int commands;             /* PSD_MQTT_COMMANDS_*: what set/<verb> may do */
	int connected, sock_ok, announce, failing, cursor_dirty, abort, closing;
	double retry_at, backoff, tokens, refill_at, saved_at;
	struct slot *q;
	size_t qcap, qhead, qn;
	long long cursor, sent;
	int backlog;
	double now;               /* the daemon's clock at the last turn */
	struct seen seen[MAX_SEEN];
	size_t nseen;
	struct stats st;
};

static struct seen *seen_of(struct psd_mqtt *m, const char *zone)
{
	for (size_t i = 0; i < m->nseen; i++)
		if (strcmp(m->seen[i].zone, zone) == 0)
			return &m->seen[i];
	if (m->nseen == MAX_SEEN)
		m->nseen = 0;     /* more zones than a config holds came and went: start over */
	memset(&m->seen[m->nseen], 0, sizeof m->seen[0]);
	snprintf(m->seen[m->nseen].zone, sizeof m->seen[0].zone, "%s", zone);
	return &m->seen[m->nseen++];
}

/* ---- the acknowledgement window ----------------------------------------------- */

static int push(struct psd_mqtt *m, int mid, long long id)
{
	if (m->qn == m->qcap)
		return -1;
	m->q[(m->qhead + m->qn) % m->qcap] = (struct slot){ mid, id, 0 };
	m->qn++;
	return 0;
}

/* Move the cursor over the acknowledged head of the window: to a sample
 * only when every message of it is acknowledged. */
static void advance(struct psd_mqtt *m)
{
	long long to = m->cursor;
	while (m->qn && m->q[m->qhead].acked) {
		long long id = m->q[m->qhead].id;
		m->qhead = (m->qhead + 1) % m->qcap;
		m->qn--;
		if (m->qn == 0 || m->q[m->qhead].id != id)
			to = id;
	}
	if (m->qn == 0)
		to = m->sent;     /* rows with nothing to publish count as done too */
	if (to > m->cursor) {
		m->cursor = to;
		m->cursor_dirty = 1;
	}
}

/* At most once a second (CURSOR_EVERY) but at close: each save is a
 * transaction in the log the control writes too; a cursor saved late only
 * means more duplicates after a crash, never a loss. */
static void save_cursor(struct psd_mqtt *m, int now)
{
	char err[256];
	double t = psd_time_mono();
	if (!m->cursor_dirty || !m->e->db || (!now && t < m->saved_at + CURSOR_EVERY))
		return;
	m->saved_at = t;
	if (m->e->log)   /* the log's writer: never waits, keeps it through a fault */
		psd_dbwriter_cursor(m->e->log, m->site, m->cursor);
	else if (psd_db_mqtt_set_cursor(m->e->db, m->site, m->cursor, err, sizeof err) != 0) {
		psd_log_warnx("mqtt: cursor: %s", err);
		return;
	}
	m->cursor_dirty = 0;
}

/* ---- publishing ------------------------------------------------------------------ */

static int publish(struct psd_mqtt *m, const char *topic, const char *payload, int retain, int *mid)
{
	int rc = mosquitto_publish(m->mosq, mid, topic, (int)strlen(payload), payload, 1, retain);
	if (rc != MOSQ_ERR_SUCCESS) {
		psd_log_debug("mqtt: publish %s: %s", topic, mosquitto_strerror(rc));
		return -1;
	}
	m->st.published++;
	return 0;
}

/* UTC on the run's clock, the one the samples are logged on (and so the
 * states' utc): one clock in the stream, also under -s, -t and -x, where it
 * is not the wall clock.  The wall clock only before the clock's date is
 * known. */
static double run_utc(const struct psd_mqtt *m)
{
	double utc = m->e->utc0 + m->now;
	return isfinite(utc) ? utc : psd_time_wall();
}

/* An event on psensd/<site>/<zone>/event (zone NULL: psensd/<site>/event). */
static int event(struct psd_mqtt *m, const char *zone, json_object *o, int *mid)
{
	char topic[TOPIC], iso[40];
	const char *text;
	int rc;
	if (zone)
		snprintf(topic, sizeof topic, "psensd/%s/%s/event", m->site, zone);
	else
		snprintf(topic, sizeof topic, "psensd/%s/event", m->site);
	if (!json_object_object_get_ex(o, "utc", NULL)) {
		psd_mqttmsg_iso8601(run_utc(m), iso, sizeof iso);
		json_object_object_add(o, "utc", json_object_new_string(iso));
	}
	text = psd_json_text(o, 10);
	rc = m->connected ? publish(m, topic, text, 0, mid) : -1;
	json_object_put(o);
	return rc;
}

static json_object *event_new(const char *what)
{
	json_object *o = json_object_new_object();
	json_object_object_add(o, "event", json_object_new_string(what));
	return o;
}

/* One logged sample: its state, and a fault event when the fault changed. */
static void row(void *user, long long id, double utc, const struct psd_sample *s)
{
	struct psd_mqtt *m = user;
	char topic[TOPIC], buf[MSG], iso[40];
	const struct psd_zone *z = NULL;
	struct seen *sn;
	int mid, faulted;
	if (m->abort)
		return;
	if (!s->zone || !psd_mqttconf_level_ok(s->zone)) {
		m->sent = id;     /* a row from before zones were logged: nothing to say */
		return;
	}
	if ((z = psd_engine_zone(m->e, s->zone)) && !(s->t >= m->now - 2 * z->zc->period))
		z = NULL;         /* live fields only for a sample just logged */
	if (psd_mqttmsg_state_json(buf, sizeof buf, m->site, id, utc, s, z,
	                           z ? psd_points_json(m->pts, m->e, (size_t)(z - m->e->zone), m->now) : NULL) < 0) {
		m->sent = id;
		return;
	}
	snprintf(topic, sizeof topic, "psensd/%s/%s/state", m->site, s->zone);
	if (publish(m, topic, buf, 0, &mid) != 0 || push(m, mid, id) != 0) {
		m->abort = 1;
		return;
	}
	m->sent = id;
	m->tokens -= 1;
	sn = seen_of(m, s->zone);
	faulted = s->fault != NULL;
	if (faulted != sn->faulted || (faulted && strcmp(sn->fault, s->fault) != 0)) {
		json_object *o = event_new(faulted ? "fault" : "fault_cleared");
		json_object_object_add(o, "id", json_object_new_int64(id));
		psd_mqttmsg_iso8601(utc, iso, sizeof iso);
		json_object_object_add(o, "utc", json_object_new_string(iso));
		json_object_object_add(o, "fault", faulted ? json_object_new_string(s->fault) : NULL);
		if (event(m, s->zone, o, &mid) != 0 || push(m, mid, id) != 0) {
			/* the state went out but not its event: send both again, and
			 * let the state's acknowledgement not move the cursor past it */
			m->abort = 1;
			m->sent = id - 1;
			m->q[(m->qhead + m->qn - 1) % m->qcap].id = id - 1;
			return;
		}
	}
	sn->faulted = faulted;
	snprintf(sn->fault, sizeof sn->fault, "%s", faulted ? s->fault : "");
}

static void publish_log(struct psd_mqtt *m)
{
	char err[256];
	double t = psd_time_mono();
	long budget;
	int n;
	if (!m->connected || !m->e->db)
		return;
	m->tokens += (t - m->refill_at) * m->rate;
	if (m->tokens > m->rate)
		m->tokens = m->rate;   /* a burst of one second at most */
	m->refill_at = t;
	budget = (long)floor(m->tokens);
	if (budget > (long)(m->qcap - m->qn) / 2)
		budget = (long)(m->qcap - m->qn) / 2;   /* each sample may take two messages */
	if (budget > BATCH)
		budget = BATCH;
	if (budget <= 0) {
		m->backlog = 1;
		return;
	}
	/* publish only what the log holds: rows of an open batch (a simulated
	 * day commits every few hundred) would be lost in a crash after the
	 * broker had them, and their ids taken again by other samples */
	if (psd_db_commit(m->e->db, err, sizeof err) != 0) {
		if (!m->failing++)
			psd_log_warnx("mqtt: committing the log: %s", err);
		return;
	}
	m->abort = 0;
	n = psd_db_samples_after(m->e->db, m->sent, (int)budget, row, m, err, sizeof err);
	if (n < 0) {
		if (!m->failing++)
			psd_log_warnx("mqtt: reading the log: %s", err);
		return;
	}
	m->failing = 0;
	m->backlog = n == budget || m->abort;
	advance(m);
}

/* Live events: a calibration session's state, the drift flag. */
static void live_events(struct psd_mqtt *m)
{
	for (size_t i = 0; i < m->e->nzone; i++) {
		const struct psd_zone *z = &m->e->zone[i];
		struct seen *sn = seen_of(m, z->zc->name);
		int mid;
		if (sn->have_live && sn->cal_state != z->cal.state) {
			json_object *o = event_new("calibration");
			json_object_object_add(o, "state",
			                       json_object_new_string(psd_calsession_state_names[z->cal.state]));
			json_object_object_add(o, "kind", json_object_new_string(psd_calsession_kind_names[z->cal.kind]));
			json_object_object_add(o, "session", z->cal.id ? json_object_new_int64(z->cal.id) : NULL);
			event(m, z->zc->name, o, &mid);
		}
		if (sn->have_live && sn->drift != z->drift.flagged) {
			json_object *o = event_new(z->drift.flagged ? "drift" : "drift_cleared");
			json_object_object_add(o, "pct", json_object_new_double(100 * (exp(z->drift.last_ln) - 1)));
			event(m, z->zc->name, o, &mid);
		}
		sn->have_live = 1;
		sn->cal_state = z->cal.state;
		sn->drift = z->drift.flagged;
	}
}

/* ---- Home Assistant discovery ------------------------------------------------------ */

struct names {
	char (*v)[PSD_MQTT_NAME];
	size_t n, cap;
};

static void add_name(void *user, const char *name)
{
	struct names *l = user;
	if (l->n < l->cap && name)
		snprintf(l->v[l->n++], PSD_MQTT_NAME, "%s", name);
}

/* 1 when the zone (user: its index, or NULL for one that left) has point i. */
struct zone_of {
	const struct psd_engine *e;
	size_t zi;
};

static int zone_has(void *user, size_t i)
{
	const struct zone_of *z = user;
	return z ? psd_points_has(z->e, z->zi, i) : 1;
}

static void discovery(struct psd_mqtt *m, const char *zone, const struct zone_of *z, int remove)
{
	char topic[TOPIC], payload[MSG];
	int mid, pt;
	for (int k = 0; psd_mqttmsg_discovery(k, m->prefix, m->site, zone, zone_has, (void *)z,
	                                   m->commands >= PSD_MQTT_COMMANDS_OVERRIDE, topic, sizeof topic, payload,
	                                   sizeof payload, &pt) == 0; k++)
		publish(m, topic, remove ? "" : payload, 1, &mid);
}

/* Announce the configured zones; remove the announced ones that left. */
static void announce(struct psd_mqtt *m)
{
	char names[MAX_SEEN][PSD_MQTT_NAME], err[256]; /* every zone, and as many that left */
	struct names l = { names, 0, MAX_SEEN };
	if (!m->e->db)
		return;
	psd_db_mqtt_announced(m->e->db, m->site, add_name, &l);
	for (size_t i = 0; i < l.n; i++) {
		if (m->discovery && psd_engine_zone(m->e, names[i]))
			continue;
		discovery(m, names[i], NULL, 1);
		if (psd_db_mqtt_announce(m->e->db, m->site, names[i], 0, err, sizeof err) != 0)
			psd_log_warnx("mqtt: %s", err);
		psd_log_info("mqtt: zone %s removed from Home Assistant discovery", names[i]);
	}
	for (size_t i = 0; m->discovery && i < m->e->nzone; i++) {
		const struct psd_zone *z = &m->e->zone[i];
		struct zone_of zo = { m->e, i };
		discovery(m, z->zc->name, &zo, 0);
		if (psd_db_mqtt_announce(m->e->db, m->site, z->zc->name, 1, err, sizeof err) != 0)
			psd_log_warnx("mqtt: %s", err);
	}
	m->announce = 0;
}

/* ---- commands ------------------------------------------------------------------------ */

static void refuse(struct psd_mqtt *m, const char *zone, const char *verb, const char *id, const char *why)
{
	json_object *o = event_new("command_refused");
	int mid;
	m->st.refused++;
	json_object_object_add(o, "command", json_object_new_string(verb));
	json_object_object_add(o, "id", id && *id ? json_object_new_string(id) : NULL);
	json_object_object_add(o, "error", json_object_new_string(why));
	psd_log_info("mqtt: set/%s for zone %s refused: %s", verb, zone ? zone : "(none)", why);
	event(m, zone && psd_mqttconf_level_ok(zone) ? zone : NULL, o, &mid);
}

static void reply(struct psd_mqtt *m, const char *zone, const char *verb, const char *id, const char *text)
{
	char topic[TOPIC];
	json_object *o = json_tokener_parse(text), *r = json_object_new_object();
	const char *out;
	int mid;
	json_object_object_add(r, "command", json_object_new_string(verb));
	json_object_object_add(r, "id", id && *id ? json_object_new_string(id) : NULL);
	json_object_object_add(r, "reply", o);
	snprintf(topic, sizeof topic, "psensd/%s/%s/reply", m->site, zone);
	out = psd_json_text(r, 10);
	publish(m, topic, out, 0, &mid);
	json_object_put(r);
}

static void on_message(struct mosquitto *mosq, void *user, const struct mosquitto_message *msg)
{
	struct psd_mqtt *m = user;
	struct psd_mqtt_cmd cmd;
	char **lev = NULL, err[512], out[4096], shown[sizeof cmd.line];
	int nlev = 0;
	const struct psd_zone *z;
	(void)mosq;
	m->st.commands++;
	if (mosquitto_sub_topic_tokenise(msg->topic, &lev, &nlev) != MOSQ_ERR_SUCCESS || nlev != 5 || !lev[0] ||
	    !lev[1] || !lev[2] || !lev[3] || !lev[4] || strcmp(lev[0], "psensd") != 0 || strcmp(lev[3], "set") != 0) {
		refuse(m, NULL, "?", NULL, "not a psensd/<site>/<zone>/set/<command> topic");
		goto done;
	}
	if (strcmp(lev[1], m->site) != 0) {
		snprintf(err, sizeof err, "command for site '%.47s' refused: this is site '%s'", lev[1], m->site);
		refuse(m, NULL, lev[4], NULL, err);
		goto done;
	}
	/* retain as published (MQTT 5): a command retained on the broker is
	 * refused whether it came at the subscription or while connected */
	if (msg->retain) {
		refuse(m, lev[2], lev[4], NULL, "a retained command is refused (it would run again at every connect)");
		goto done;
	}
	if (psd_mqttcmd_scope(m->grants(lev[4])) > m->commands) {
		snprintf(err, sizeof err, "set/%.24s is not allowed: [mqtt] commands = override (override, release, "
		         "status)", lev[4]);
		refuse(m, lev[2], lev[4], NULL, err);
		goto done;
	}
	z = psd_mqttconf_level_ok(lev[2]) ? psd_engine_zone(m->e, lev[2]) : NULL;
	if (psd_mqttcmd_parse(m->site, lev[2], lev[4], msg->payload, (size_t)msg->payloadlen,
	                       z ? z->zc->override_s : 3600, &cmd, err, sizeof err) != 0) {
		refuse(m, lev[2], lev[4], cmd.id, err);
		goto done;
	}
	snprintf(shown, sizeof shown, "%s", cmd.line);   /* the request's words, which fn splits */
	m->fn(m->user, cmd.line, out, sizeof out);
	reply(m, lev[2], lev[4], cmd.id, out);
	if (!strstr(out, "\"ok\":true")) {
		json_object *r = json_tokener_parse(out), *e;
		const char *why = r && json_object_object_get_ex(r, "error", &e) ? json_object_get_string(e) : out;
		refuse(m, lev[2], lev[4], cmd.id, why);
		json_object_put(r);
	} else {
		psd_log_info("mqtt: set/%s for zone %s: %s", lev[4], lev[2], shown);
	}
done:
	mosquitto_sub_topic_tokens_free(&lev, nlev);
}

/* ---- the connection ------------------------------------------------------------------- */

static void lost(struct psd_mqtt *m, const char *why)
{
	if (m->connected && !m->closing)
		psd_log_warnx("mqtt: connection lost (%s): publishing resumes from sample %lld when it is back", why,
		          m->cursor);
	m->connected = 0;
	m->sock_ok = 0;
	m->qn = 0;
	m->sent = m->cursor;      /* what was not acknowledged goes again */
	/* and its fault events with it: as at a start, a zone is taken to be
	 * without a fault until a sample says otherwise (an event may come
	 * twice, with the same id; none is skipped) */
	for (size_t i = 0; i < m->nseen; i++)
		m->seen[i].faulted = 0;
	m->retry_at = psd_time_mono() + m->backoff;
	m->backoff = m->backoff * 2 > RETRY_MAX ? RETRY_MAX : m->backoff * 2;
}

static void on_connect(struct mosquitto *mosq, void *user, int rc)
{
	struct psd_mqtt *m = user;
	char topic[TOPIC];
	int mid;
	if (rc != 0) {
		if (!m->failing++)
			psd_log_warnx("mqtt: the broker refused the connection: %s", mosquitto_connack_string(rc));
		return;   /* the broker closes it; lost() follows */
	}
	m->failing = 0;
	m->connected = 1;
	m->st.connects++;
	m->backoff = RETRY_MIN;
	m->qn = 0;
	m->sent = m->cursor;
	m->announce = 1;
	m->refill_at = psd_time_mono();
	psd_log_info("mqtt: connected; publishing from sample %lld", m->cursor);
	snprintf(topic, sizeof topic, "psensd/%s/+/set/+", m->site);
	if (m->commands != PSD_MQTT_COMMANDS_NONE)
		mosquitto_subscribe_v5(mosq, &mid, topic, 1, MQTT_SUB_OPT_RETAIN_AS_PUBLISHED, NULL);
	publish(m, m->status_topic, "online", 1, &mid);
}

static void on_disconnect(struct mosquitto *mosq, void *user, int rc)
{
	(void)mosq;
	lost(user, rc ? mosquitto_strerror(rc) : "disconnected");
}

static void on_publish(struct mosquitto *mosq, void *user, int mid)
{
	struct psd_mqtt *m = user;
	(void)mosq;
	for (size_t i = 0; i < m->qn; i++) {
		struct slot *s = &m->q[(m->qhead + i) % m->qcap];
		if (s->mid == mid && !s->acked) {
			s->acked = 1;
			m->st.acked++;
			break;
		}
	}
}

static void try_connect(struct psd_mqtt *m)
{
	int rc = mosquitto_reconnect_async(m->mosq);
	if (rc == MOSQ_ERR_SUCCESS) {
		m->sock_ok = 1;
		return;
	}
	if (!m->failing++)
		psd_log_warnx("mqtt: cannot connect: %s; trying again every %g s at most", rc == MOSQ_ERR_ERRNO
		          ? strerror(errno) : mosquitto_strerror(rc), RETRY_MAX);
	lost(m, "connect");
}

static struct psd_mqtt *mqtt_open(const struct psd_mqtt_conf *c, struct psd_engine *e, const struct psd_points *pts,
                                  psd_frontend_fixed_fn fn, psd_frontend_grants_fn grants, void *user, char *err,
                                  size_t errlen)
{
	struct psd_mqtt *m;
	char id[128];
	int rc;
	if (!e->db) {
		psd_errbuf(err, errlen, "[mqtt] needs the sample log: set database in [psensd]");
		return NULL;
	}
	if (!(m = calloc(1, sizeof *m)) || !(m->q = calloc((size_t)c->inflight + 2, sizeof *m->q))) {
		free(m);
		psd_errbuf(err, errlen, "mqtt: out of memory");
		return NULL;
	}
	m->qcap = (size_t)c->inflight + 2;
	m->now = NAN;   /* no turn yet: events carry the wall clock (run_utc) */
	m->e = e;
	m->pts = pts;
	m->fn = fn;
	m->grants = grants;
	m->user = user;
	snprintf(m->site, sizeof m->site, "%s", c->site);
	snprintf(m->prefix, sizeof m->prefix, "%s", c->discovery_prefix);
	snprintf(m->status_topic, sizeof m->status_topic, "psensd/%s/status", c->site);
	m->rate = c->rate;
	m->inflight = c->inflight;
	m->discovery = c->discovery;
	m->commands = c->commands;
	m->backoff = RETRY_MIN;
	m->cursor = psd_db_mqtt_cursor(e->db, m->site);
	if (m->cursor < 0) {
		psd_errbuf(err, errlen, "mqtt: cannot read the cursor from the log");
		goto bad;
	}
	m->sent = m->cursor;
	mosquitto_lib_init();
	snprintf(id, sizeof id, "psensd-%s", c->site);
	if (!(m->mosq = mosquitto_new(id, true, m))) {
		psd_errbuf(err, errlen, "mqtt: %s", strerror(errno));
		goto bad;
	}
	mosquitto_connect_callback_set(m->mosq, on_connect);
	mosquitto_disconnect_callback_set(m->mosq, on_disconnect);
	mosquitto_publish_callback_set(m->mosq, on_publish);
	mosquitto_message_callback_set(m->mosq, on_message);
	mosquitto_max_inflight_messages_set(m->mosq, (unsigned)c->inflight + 8);
	/* commands need MQTT 5: only its "retain as published" subscription
	 * tells a command retained while psensd is connected; telemetry alone
	 * speaks 3.1.1 to any broker */
	if (m->commands != PSD_MQTT_COMMANDS_NONE)
		mosquitto_int_option(m->mosq, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V5);
	if ((rc = mosquitto_will_set(m->mosq, m->status_topic, 7, "offline", 1, true)) != MOSQ_ERR_SUCCESS ||
	    (c->user && (rc = mosquitto_username_pw_set(m->mosq, c->user, c->password)) != MOSQ_ERR_SUCCESS) ||
	    (c->cafile && (rc = mosquitto_tls_set(m->mosq, c->cafile, NULL, c->certfile, c->keyfile, NULL)) !=
	                      MOSQ_ERR_SUCCESS)) {
		psd_errbuf(err, errlen, "mqtt: %s", rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
		goto bad;
	}
	rc = mosquitto_connect_async(m->mosq, c->host, (int)c->port, (int)c->keepalive);
	if (rc == MOSQ_ERR_SUCCESS) {
		m->sock_ok = 1;
	} else if (rc == MOSQ_ERR_INVAL || rc == MOSQ_ERR_NOMEM) {
		psd_errbuf(err, errlen, "mqtt: %s:%ld: %s", c->host, c->port, mosquitto_strerror(rc));
		goto bad;
	} else {
		psd_log_warnx("mqtt: %s:%ld: %s; trying again every %g s at most", c->host, c->port,
		          rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc), RETRY_MAX);
		m->failing = 1;
		lost(m, "connect");
	}
	psd_log_info("mqtt: site %s, broker %s:%ld%s, from sample %lld, commands %s", m->site, c->host, c->port,
	         c->cafile ? " (TLS)" : "", m->cursor, m->commands == PSD_MQTT_COMMANDS_ALL ? "all"
	         : m->commands == PSD_MQTT_COMMANDS_OVERRIDE ? "override (override, release, status)"
	         : "none (not subscribed)");
	return m;
bad:
	if (m->mosq)
		mosquitto_destroy(m->mosq);
	free(m->q);
	free(m);
	return NULL;
}

static int mqtt_pollfd(struct psd_mqtt *m, struct pollfd *pfd)
{
	int fd = m->sock_ok ? mosquitto_socket(m->mosq) : -1;
	if (fd < 0)
		return 0;
	*pfd = (struct pollfd){ fd, (short)(POLLIN | (mosquitto_want_write(m->mosq) ? POLLOUT : 0)), 0 };
	return 1;
}

static void service(struct psd_mqtt *m, const struct pollfd *pfd, double now);

static void mqtt_service(struct psd_mqtt *m, const struct pollfd *pfd, double now)
{
	double t0 = psd_time_mono(), c0 = psd_time_thread_cpu(), dt, dc;
	service(m, pfd, now);
	if ((dt = psd_time_mono() - t0) > m->st.turn_max)
		m->st.turn_max = dt;
	if ((dc = psd_time_thread_cpu() - c0) > m->st.turn_cpu_max)
		m->st.turn_cpu_max = dc;
}

static void service(struct psd_mqtt *m, const struct pollfd *pfd, double now)
{
	int rc;
	m->now = now;
	if (pfd && m->sock_ok && (pfd->revents & (POLLIN | POLLHUP | POLLERR))) {
		if ((rc = mosquitto_loop_read(m->mosq, 16)) != MOSQ_ERR_SUCCESS)
			lost(m, rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
	}
	if (m->sock_ok && mosquitto_want_write(m->mosq) && (!pfd || (pfd->revents & POLLOUT))) {
		if ((rc = mosquitto_loop_write(m->mosq, 16)) != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_NO_CONN)
			lost(m, rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
	}
	if (m->sock_ok) {
		mosquitto_loop_misc(m->mosq);
		if (mosquitto_socket(m->mosq) < 0)
			lost(m, "closed");
	}
	if (!m->sock_ok && psd_time_mono() >= m->retry_at)
		try_connect(m);
	advance(m);
	if (m->connected) {
		if (m->announce)
			announce(m);
		publish_log(m);
		live_events(m);
		/* write what was queued now rather than at the next POLLOUT */
		if (mosquitto_want_write(m->mosq) && (rc = mosquitto_loop_write(m->mosq, 16)) != MOSQ_ERR_SUCCESS &&
		    rc != MOSQ_ERR_NO_CONN)
			lost(m, mosquitto_strerror(rc));
	}
	save_cursor(m, 0);
}

static int mqtt_wait_ms(const struct psd_mqtt *m)
{
	double ms = 1000;
	if (!m->sock_ok)
		ms = 1000 * (m->retry_at - psd_time_mono());
	else if (m->connected && m->backlog && (m->qcap - m->qn) / 2 >= 1)
		ms = 1000 * (1 - m->tokens) / m->rate;   /* the next token (a full window waits for PUBACKs) */
	if (ms < 1)
		ms = 1;
	return ms > 1000 ? 1000 : (int)ms;
}

static void mqtt_reload(struct psd_mqtt *m)
{
	int mid;
	m->announce = 1;
	for (size_t i = 0; i < m->nseen; i++)
		m->seen[i].have_live = 0;
	event(m, NULL, event_new("reload"), &mid);
}

static void mqtt_stats(const struct psd_mqtt *m, struct stats *st)
{
	*st = m->st;
	st->connected = m->connected;
	st->cursor = m->cursor;
	st->sent = m->sent;
}

static void mqtt_close(struct psd_mqtt *m)
{
	int mid;
	if (!m)
		return;
	m->closing = 1;
	if (m->connected) {
		double until = psd_time_mono() + 1;
		publish(m, m->status_topic, "offline", 1, &mid);
		/* a second at most for the last acknowledgements and the offline */
		while (m->connected && psd_time_mono() < until && (m->qn || mosquitto_want_write(m->mosq))) {
			if (mosquitto_loop(m->mosq, 50, 16) != MOSQ_ERR_SUCCESS)
				break;
			advance(m);
		}
		mosquitto_disconnect(m->mosq);
		mosquitto_loop(m->mosq, 50, 1);
	}
	save_cursor(m, 1);
	mosquitto_destroy(m->mosq);
	mosquitto_lib_cleanup();
	free(m->q);
	free(m);
}

/* ---- the room's row (frontend.h) ---- */

static int wanted(const struct psd_config *cf)
{
	return cf->mqtt.enabled;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	return mqtt_open(&env->cf->mqtt, env->engine, env->points, env->fixed, env->grants, env->user, err, errlen);
}

/* the samples just logged go out now, within the bounds */
static void step(void *fe, double now)
{
	mqtt_service(fe, NULL, now);
}

static int pollfds(void *fe, struct pollfd *fds, int max)
{
	return max > 0 ? mqtt_pollfd(fe, fds) : 0;
}

static int wait_ms(const void *fe)
{
	return mqtt_wait_ms(fe);
}

static void turn(void *fe, const struct pollfd *fds, int n, double now)
{
	(void)n;
	mqtt_service(fe, fds, now);
}

/* a client started at the start stays its configuration's until a restart */
static void reload(void *fe, const struct psd_config *cf)
{
	if (fe)
		mqtt_reload(fe);
	if (cf->mqtt.enabled != (fe != NULL))
		psd_log_warnx("reload: [mqtt] was %s: that takes effect at a restart", cf->mqtt.enabled ? "added" : "removed");
}

static void status(const void *fe, json_object *o)
{
	struct stats ms;
	json_object *mq = json_object_new_object();
	mqtt_stats(fe, &ms);
	json_object_object_add(mq, "connected", json_object_new_boolean(ms.connected));
	json_object_object_add(mq, "cursor", json_object_new_int64(ms.cursor));
	json_object_object_add(mq, "sent", json_object_new_int64(ms.sent));
	json_object_object_add(mq, "published", json_object_new_int64((int64_t)ms.published));
	json_object_object_add(mq, "acked", json_object_new_int64((int64_t)ms.acked));
	json_object_object_add(mq, "commands", json_object_new_int64((int64_t)ms.commands));
	json_object_object_add(mq, "refused", json_object_new_int64((int64_t)ms.refused));
	json_object_object_add(mq, "connects", json_object_new_int64((int64_t)ms.connects));
	psd_json_num(mq, "turn_max_s", ms.turn_max);
	psd_json_num(mq, "turn_cpu_max_s", ms.turn_cpu_max);
	json_object_object_add(o, "mqtt", mq);
}

/* offline published, the last acknowledgements, while the log is open */
static void stop(void *fe)
{
	mqtt_close(fe);
}

const struct psd_frontend psd_mqtt_frontend = {
	.name = "mqtt",
	.refused = "MQTT cannot start",
	.wanted = wanted,
	.start = start,
	.step = step,
	.pollfds = pollfds,
	.wait_ms = wait_ms,
	.service = turn,
	.reload = reload,
	.status = status,
	.stop = stop,
};
