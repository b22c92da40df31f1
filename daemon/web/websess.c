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

void psd_websess_revoke(struct psd_websess *s, const char *token, double now)
{
	size_t k = 0;
	const char *dot1 = strchr(token, '.');
	if (!psd_websess_valid(s, token, now, NULL))
		return;
	for (size_t i = 0; i < PSD_WEBSESS_REVOKED; i++) {   /* a free or expired slot, else the soonest to expire */
		if (s->revoked[i].expiry <= now) {
			k = i;
			break;
		}
		if (s->revoked[i].expiry < s->revoked[k].expiry)
			k = i;
	}
	memcpy(s->revoked[k].nonce, dot1 + 1, 16);
	s->revoked[k].nonce[16] = 0;
	s->revoked[k].expiry = (double)strtoll(token, NULL, 10);
}

static int guard_find(const struct psd_websess *s, const char *addr)
{
	for (int i = 0; i < PSD_WEBSESS_ADDRS; i++)
		if (s->guard[i].addr[0] && strcmp(s->guard[i].addr, addr) == 0)
			return i;
	return -1;
}

double psd_websess_wait(const struct psd_websess *s, const char *addr, double now)
{
	int i = guard_find(s, addr);
	return i >= 0 && s->guard[i].until > now ? s->guard[i].until - now : 0;
}

void psd_websess_outcome(struct psd_websess *s, const char *addr, int ok, double now)
{
	int i = guard_find(s, addr);
	if (ok) {
		if (i >= 0)
			memset(&s->guard[i], 0, sizeof s->guard[i]);
		return;
	}
	if (i < 0) {   /* a free slot, else the one idle longest */
		i = 0;
		for (int k = 0; k < PSD_WEBSESS_ADDRS; k++) {
			if (!s->guard[k].addr[0]) {
				i = k;
				break;
			}
			if (s->guard[k].last < s->guard[i].last)
				i = k;
		}
		memset(&s->guard[i], 0, sizeof s->guard[i]);
		snprintf(s->guard[i].addr, sizeof s->guard[i].addr, "%s", addr);
	}
	s->guard[i].fails++;
	s->guard[i].last = now;
	if (s->guard[i].fails >= PSD_WEBSESS_FREE_FAILS) {
		int over = s->guard[i].fails - PSD_WEBSESS_FREE_FAILS;
		double delay = over >= 6 ? PSD_WEBSESS_MAX_DELAY : fmin(PSD_WEBSESS_MAX_DELAY, (double)(1 << over));
		s->guard[i].until = now + delay;
	}
}
