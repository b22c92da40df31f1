/* SPDX-License-Identifier: ISC */
/* The web console's sessions and its guard against password guessing.
 *
 * A session is a signed token in an HttpOnly cookie:
 *   EXPIRY.NONCE.MAC   (Unix seconds, 16 random hex digits, HMAC-SHA256)
 * keyed by a key derived from the stored password hash, so a session
 * outlives a restart of psensd (the page reconnects and goes on) and a new
 * password ends every session.  Logging out revokes the token's nonce in
 * memory until the token expires; the table holds PSD_WEBSESS_REVOKED of
 * them, and a logout that finds it full of unexpired ones changes the key
 * (random, for this run of psensd), which ends every session, rather than
 * forget a revocation.
 *
 * Failed logins are counted by address (PSD_WEBSESS_ADDRS of them); the
 * addresses that find the table full share one more count, so that no
 * address's failures are ever forgotten to make room.  Over every address
 * the failures are a leaky bucket: PSD_WEBSESS_BURST at once, then
 * PSD_WEBSESS_RATE a second.  Times are wall-clock Unix seconds, passed
 * in. */
#ifndef PSD_WEBSESS_H
#define PSD_WEBSESS_H

#include <stddef.h>

enum { PSD_WEBSESS_TOKEN = 112, PSD_WEBSESS_REVOKED = 256, PSD_WEBSESS_ADDRS = 32, PSD_WEBSESS_FREE_FAILS = 3,
       PSD_WEBSESS_MAX_DELAY = 60, PSD_WEBSESS_BURST = 30 };
#define PSD_WEBSESS_RATE 0.5   /* failed logins a second over every address, after the burst */

struct psd_websess_guard {
	char addr[48];
	int fails;
	double until, last;
};

struct psd_websess {
	unsigned char key[32];
	double lifetime;   /* s */
	struct { char nonce[17]; double expiry; } revoked[PSD_WEBSESS_REVOKED];
	/* failed logins by client address: after PSD_WEBSESS_FREE_FAILS of them,
	 * the next attempt waits 1, 2, 4 ... up to PSD_WEBSESS_MAX_DELAY s */
	struct psd_websess_guard guard[PSD_WEBSESS_ADDRS];
	struct psd_websess_guard rest;   /* the addresses that found no room */
	double bucket, bucket_at;        /* failures in the global bucket, when */
	unsigned rotations;              /* key changes after a full revocation table */
};

/* Key the sessions from the stored password hash line; lifetime in s. */
void psd_websess_init(struct psd_websess *s, const char *hash_line, double lifetime);
/* A new token (PSD_WEBSESS_TOKEN bytes) valid from now for the lifetime.
 * -1 and errno when no random bytes. */
int psd_websess_issue(struct psd_websess *s, double now, char *token, size_t n);
/* 1 when token is signed, unexpired and not revoked; else 0, with why
 * ("expired" or "invalid") in why when given. */
int psd_websess_valid(const struct psd_websess *s, const char *token, double now, const char **why);
/* Revoke a token (log out): 0, or 1 when the table was full and the key
 * changed (every session ended). */
int psd_websess_revoke(struct psd_websess *s, const char *token, double now);
/* Seconds addr must still wait before a login is judged, 0 none. */
double psd_websess_wait(const struct psd_websess *s, const char *addr, double now);
/* Seconds every address must still wait (the global rate), 0 none. */
double psd_websess_wait_all(const struct psd_websess *s, double now);
/* Count a login's outcome for addr (ok 1: its failures are forgotten). */
void psd_websess_outcome(struct psd_websess *s, const char *addr, int ok, double now);

#endif
