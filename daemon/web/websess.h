/* SPDX-License-Identifier: ISC */
/* The web console's sessions and its guard against password guessing.
 *
 * A session is a signed token in an HttpOnly cookie:
 *   EXPIRY.NONCE.MAC   (Unix seconds, 16 random hex digits, HMAC-SHA256)
 * keyed by a key derived from the stored password hash, so a session
 * outlives a restart of psensd (the page reconnects and goes on) and a new
 * password ends every session.  Logging out revokes the token's nonce in
 * memory until it expires.  Times are wall-clock Unix seconds, passed in. */
#ifndef PSD_WEBSESS_H
#define PSD_WEBSESS_H

#include <stddef.h>

enum { PSD_WEBSESS_TOKEN = 112, PSD_WEBSESS_REVOKED = 64, PSD_WEBSESS_ADDRS = 32, PSD_WEBSESS_FREE_FAILS = 3,
       PSD_WEBSESS_MAX_DELAY = 60 };

struct psd_websess {
	unsigned char key[32];
	double lifetime;   /* s */
	struct { char nonce[17]; double expiry; } revoked[PSD_WEBSESS_REVOKED];
	/* failed logins by client address: after PSD_WEBSESS_FREE_FAILS of them,
	 * the next attempt waits 1, 2, 4 ... up to PSD_WEBSESS_MAX_DELAY s */
	struct { char addr[48]; int fails; double until, last; } guard[PSD_WEBSESS_ADDRS];
};

/* Key the sessions from the stored password hash line; lifetime in s. */
void psd_websess_init(struct psd_websess *s, const char *hash_line, double lifetime);
/* A new token (PSD_WEBSESS_TOKEN bytes) valid from now for the lifetime.
 * -1 and errno when no random bytes. */
int psd_websess_issue(struct psd_websess *s, double now, char *token, size_t n);
/* 1 when token is signed, unexpired and not revoked; else 0, with why
 * ("expired" or "invalid") in why when given. */
int psd_websess_valid(const struct psd_websess *s, const char *token, double now, const char **why);
/* Revoke a token (log out). */
void psd_websess_revoke(struct psd_websess *s, const char *token, double now);
/* Seconds addr must still wait before a login is judged, 0 none. */
double psd_websess_wait(const struct psd_websess *s, const char *addr, double now);
/* Count a login's outcome for addr (ok 1: its failures are forgotten). */
void psd_websess_outcome(struct psd_websess *s, const char *addr, int ok, double now);

#endif
