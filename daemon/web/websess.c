/* SPDX-License-Identifier: ISC */
#include "websess.h"

#include <math.h>
#include <nettle/hmac.h>
#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

static const char context[] = "psensd web console session key";

void psd_websess_init(struct psd_websess *s, const char *hash_line, double lifetime)
{
	struct sha256_ctx h;
	memset(s, 0, sizeof *s);
	sha256_init(&h);
	sha256_update(&h, sizeof context, (const uint8_t *)context);
	sha256_update(&h, strlen(hash_line), (const uint8_t *)hash_line);
	sha256_digest(&h, sizeof s->key, s->key);
	s->lifetime = lifetime;
}

static void mac_hex(const struct psd_websess *s, const char *msg, size_t len, char out[65])
{
	struct hmac_sha256_ctx h;
	unsigned char d[SHA256_DIGEST_SIZE];
	hmac_sha256_set_key(&h, sizeof s->key, s->key);
	hmac_sha256_update(&h, len, (const uint8_t *)msg);
	hmac_sha256_digest(&h, sizeof d, d);
	for (size_t i = 0; i < sizeof d; i++)
		snprintf(out + 2 * i, 3, "%02x", d[i]);
}

int psd_websess_issue(struct psd_websess *s, double now, char *token, size_t n)
{
	unsigned char r[8];
	char body[64], mac[65];
	int k;
	if (getrandom(r, sizeof r, 0) != (ssize_t)sizeof r)
		return -1;
	k = snprintf(body, sizeof body, "%.0f.%02x%02x%02x%02x%02x%02x%02x%02x", floor(now + s->lifetime), r[0], r[1],
	             r[2], r[3], r[4], r[5], r[6], r[7]);
	mac_hex(s, body, (size_t)k, mac);
	snprintf(token, n, "%s.%s", body, mac);
	return 0;
}

int psd_websess_valid(const struct psd_websess *s, const char *token, double now, const char **why)
{
	const char *dot2, *dot1 = strchr(token, '.');
	char mac[65], *end;
	unsigned char diff = 0;
	double expiry;
	if (why)
		*why = "invalid";
	if (!dot1 || !(dot2 = strchr(dot1 + 1, '.')) || dot2 - dot1 != 17 || strlen(dot2 + 1) != 64)
		return 0;
	mac_hex(s, token, (size_t)(dot2 - token), mac);
	for (size_t i = 0; i < 64; i++)
		diff |= (unsigned char)(mac[i] ^ dot2[1 + i]);
	if (diff)
		return 0;
	expiry = (double)strtoll(token, &end, 10);   /* not strtod: it would take the dot */
	if (end != dot1)
		return 0;
	for (size_t i = 0; i < PSD_WEBSESS_REVOKED; i++)
		if (s->revoked[i].expiry > 0 && strncmp(s->revoked[i].nonce, dot1 + 1, 16) == 0)
			return 0;
	if (now >= expiry) {
		if (why)
			*why = "expired";
		return 0;
	}
	return 1;
}

/* A new key for the rest of this run: every token signed so far is
 * refused, so the revocations can all be forgotten.  Random when the
 * kernel gives random bytes, and always a hash of the old key, so never
 * the old key again. */
static void rotate(struct psd_websess *s)
{
	static const char why[] = "psensd web console key after a full revocation table";
	struct sha256_ctx h;
	unsigned char r[32] = { 0 };
	if (getrandom(r, sizeof r, 0) != (ssize_t)sizeof r)
		memset(r, 0, sizeof r);
	sha256_init(&h);
	sha256_update(&h, sizeof why, (const uint8_t *)why);
	sha256_update(&h, sizeof s->key, s->key);
	sha256_update(&h, sizeof r, r);
	sha256_digest(&h, sizeof s->key, s->key);
	memset(s->revoked, 0, sizeof s->revoked);
	s->rotations++;
}

int psd_websess_revoke(struct psd_websess *s, const char *token, double now)
{
	const char *dot1 = strchr(token, '.');
	if (!psd_websess_valid(s, token, now, NULL))
		return 0;
	for (size_t i = 0; i < PSD_WEBSESS_REVOKED; i++)   /* a free or expired slot */
		if (s->revoked[i].expiry <= now) {
			memcpy(s->revoked[i].nonce, dot1 + 1, 16);
			s->revoked[i].nonce[16] = 0;
			s->revoked[i].expiry = (double)strtoll(token, NULL, 10);
			return 0;
		}
	rotate(s);   /* none: overwriting one would bring its token back */
	return 1;
}

static int guard_find(const struct psd_websess *s, const char *addr)
{
	for (int i = 0; i < PSD_WEBSESS_ADDRS; i++)
		if (s->guard[i].addr[0] && strcmp(s->guard[i].addr, addr) == 0)
			return i;
	return -1;
}

static int guard_free(const struct psd_websess *s)
{
	for (int i = 0; i < PSD_WEBSESS_ADDRS; i++)
		if (!s->guard[i].addr[0])
			return i;
	return -1;
}

/* addr's count: its own, or, while the shared one holds failures or no
 * slot is free, the shared one (so that an address counted there does not
 * start again from nothing when a slot frees). */
static const struct psd_websess_guard *guard_of(const struct psd_websess *s, const char *addr)
{
	int i = guard_find(s, addr);
	if (i >= 0)
		return &s->guard[i];
	if (s->rest.fails > 0 || guard_free(s) < 0)
		return &s->rest;
	return NULL;
}

double psd_websess_wait(const struct psd_websess *s, const char *addr, double now)
{
	const struct psd_websess_guard *g = guard_of(s, addr);
	return g && g->until > now ? g->until - now : 0;
}

/* The global bucket's level now, after its leak since the last failure. */
static double bucket_level(const struct psd_websess *s, double now)
{
	return fmax(0, s->bucket - (now - s->bucket_at) * PSD_WEBSESS_RATE);
}

double psd_websess_wait_all(const struct psd_websess *s, double now)
{
	double over = bucket_level(s, now) + 1 - PSD_WEBSESS_BURST;   /* a failure more would overflow it */
	return over > 0 ? over / PSD_WEBSESS_RATE : 0;
}

void psd_websess_outcome(struct psd_websess *s, const char *addr, int ok, double now)
{
	struct psd_websess_guard *g = (struct psd_websess_guard *)guard_of(s, addr);
	if (ok) {   /* forgets only an address's own count: the shared one is others' too */
		if (g && g != &s->rest)
			memset(g, 0, sizeof *g);
		return;
	}
	s->bucket = bucket_level(s, now) + 1;
	s->bucket_at = now;
	if (!g) {
		g = &s->guard[guard_free(s)];
		snprintf(g->addr, sizeof g->addr, "%s", addr);
	}
	g->fails++;
	g->last = now;
	if (g->fails >= PSD_WEBSESS_FREE_FAILS) {
		int over = g->fails - PSD_WEBSESS_FREE_FAILS;
		double delay = over >= 6 ? PSD_WEBSESS_MAX_DELAY : fmin(PSD_WEBSESS_MAX_DELAY, (double)(1 << over));
		g->until = now + delay;
	}
}
