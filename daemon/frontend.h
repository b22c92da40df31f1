/* SPDX-License-Identifier: ISC */
/* The front ends' table: every protocol or console psensd serves beside
 * its control socket (MQTT, BACnet, the web console, the Prometheus
 * textfile) is one row, and the loop walks the table for everything it does
 * with them: start, the turn after the engine's step, the poll set and its
 * timeout, the service after poll(), a reload, status, stop.
 *
 * A row lives in its room (daemon/X/X.c exports psd_X_frontend, declared in
 * X.h); frontend.c's table lists every front end compiled into psensd, in
 * the order they start (they stop in the reverse order).  A hook a front end has no use for is NULL. */
#ifndef PSD_FRONTEND_H
#define PSD_FRONTEND_H

#include <poll.h>
#include <stddef.h>

struct psd_config;
struct psd_ctl_reply;
struct psd_engine;
struct psd_points;
struct json_object;

/* A control request (psd_cmdtab_request), its reply copied into a fixed
 * buffer (an error reply when it does not fit), or growing as it needs. */
typedef void (*psd_frontend_fixed_fn)(void *user, char *line, char *reply, size_t len);
typedef void (*psd_frontend_request_fn)(void *user, char *line, struct psd_ctl_reply *reply);
/* The front ends a command word grants (psd_cmdtab_verb_fronts): MQTT's
 * verbs are checked against the command table, handed in so that the room
 * calls no core function. */
typedef unsigned (*psd_frontend_grants_fn)(const char *verb);
/* The command table's typed entries (psd_cmdtab_override, _release), for a
 * front end whose values are typed (BACnet), handed in the same way. */
typedef int (*psd_frontend_override_fn)(struct psd_engine *e, const char *zone, double level, double seconds,
                                        double now, char *err, size_t errlen);
typedef int (*psd_frontend_release_fn)(struct psd_engine *e, const char *zone, char *err, size_t errlen);

/* What a front end is given at its start: the configuration (freed at a
 * reload: keep what is needed, or read engine->cf), the engine and the
 * point model it serves, and the core's one way in for commands. */
struct psd_frontend_env {
	const struct psd_config *cf;
	struct psd_engine *engine;
	const struct psd_points *points;
	psd_frontend_fixed_fn fixed;
	psd_frontend_request_fn request;
	psd_frontend_grants_fn grants;
	psd_frontend_override_fn override;
	psd_frontend_release_fn release;
	void *user;
};

struct psd_frontend {
	const char *name;        /* its configuration section, e.g. "mqtt" */
	const char *refused;     /* the safe level's reason when it cannot start */
	/* the configuration asks for it */
	int (*wanted)(const struct psd_config *cf);
	/* its state, or NULL with a message in err */
	void *(*start)(const struct psd_frontend_env *env, char *err, size_t errlen);
	/* after each engine step, before poll(): what the step produced goes out */
	void (*step)(void *fe, double now);
	/* its descriptors for poll(), at most max: the count written */
	int (*pollfds)(void *fe, struct pollfd *fds, int max);
	/* wall milliseconds until it wants a turn, -1 none */
	int (*wait_ms)(const void *fe);
	/* after poll(): fds its n descriptors with their revents (NULL when 0) */
	void (*service)(void *fe, const struct pollfd *fds, int n, double now);
	/* the engine was reopened on cf; fe NULL: the front end is not running */
	void (*reload)(void *fe, const struct psd_config *cf);
	/* its part of status -j, added to o */
	void (*status)(const void *fe, struct json_object *o);
	/* close and free (what is left to send, sent first) */
	void (*stop)(void *fe);
};

enum { PSD_FRONTEND_MAX = 8 };

/* The running front ends: rows (NULL-terminated; NULL: frontend.c's table,
 * which a test may replace with its own), each one's state (NULL: not running) and its count
 * of descriptors in this turn's poll set. */
struct psd_frontend_set {
	const struct psd_frontend *const *rows;
	void *fe[PSD_FRONTEND_MAX];
	int nfd[PSD_FRONTEND_MAX];
};

/* Start every row the configuration wants, in order.  -1 at the first that
 * cannot, with its message in err and its row in *failed: the ones started
 * before it are still running, for psd_frontend_stop. */
int psd_frontend_start(struct psd_frontend_set *s, const struct psd_frontend_env *env,
                       const struct psd_frontend **failed, char *err, size_t errlen);
/* Stop every running front end, in the reverse order of their start. */
void psd_frontend_stop(struct psd_frontend_set *s);
/* The turn after the engine's step. */
void psd_frontend_step(struct psd_frontend_set *s, double now);
/* Their descriptors into fds (at most max), *timeout_ms (-1 infinite)
 * lowered to the soonest turn one wants.  Returns the count written. */
int psd_frontend_pollfds(struct psd_frontend_set *s, struct pollfd *fds, int max, int *timeout_ms);
/* After poll(): fds is what psd_frontend_pollfds filled. */
void psd_frontend_service(struct psd_frontend_set *s, const struct pollfd *fds, double now);
void psd_frontend_reload(struct psd_frontend_set *s, const struct psd_config *cf);
void psd_frontend_status(const struct psd_frontend_set *s, struct json_object *o);

#endif
