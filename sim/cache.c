#include "cache.h"

#include <errno.h>
#include <math.h>
#include <nettle/sha2.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void to_hex(const uint8_t *d, char hex[65])
{
	static const char digits[] = "0123456789abcdef";
	for (int i = 0; i < 32; i++) {
		hex[2 * i] = digits[d[i] >> 4];
		hex[2 * i + 1] = digits[d[i] & 15];
	}
	hex[64] = '\0';
}

int ps_hash_file(const char *path, char hex[65], struct ps_err *e)
{
	struct sha256_ctx ctx;
	uint8_t buf[65536], d[SHA256_DIGEST_SIZE];
	size_t n;
	FILE *fp = fopen(path, "rb");
	if (!fp)
		return ps_errsys(e, "%s", path);
	sha256_init(&ctx);
	while ((n = fread(buf, 1, sizeof buf, fp)) > 0)
		sha256_update(&ctx, n, buf);
	if (ferror(fp)) {
		int rc = ps_errsys(e, "%s: read error", path);
		fclose(fp);
		return rc;
	}
	fclose(fp);
	sha256_digest(&ctx, sizeof d, d);
	to_hex(d, hex);
	return 0;
}

void ps_hash_string(const char *s, char hex[65])
{
	struct sha256_ctx ctx;
	uint8_t d[SHA256_DIGEST_SIZE];
	sha256_init(&ctx);
	sha256_update(&ctx, strlen(s), (const uint8_t *)s);
	sha256_digest(&ctx, sizeof d, d);
	to_hex(d, hex);
}

static void entry_path(const char *dir, const char *key, char *out, size_t len)
{
	char h[65];
	ps_hash_string(key, h);
	snprintf(out, len, "%s/%.2s/%s", dir, h, h + 2);
}

/* An entry: "psscene-cache 1", the key, then the n numbers. */
static int entry_parse(FILE *fp, const char *key, double *v, int n)
{
	char line[256];
	int got = 0;
	/* first line: the key itself, so a hash collision cannot go unnoticed */
	if (!fgets(line, sizeof line, fp) || strncmp(line, "psscene-cache 1", 15) != 0)
		return 0;
	{
		char *k = malloc(strlen(key) + 3);
		if (!k || !fgets(k, (int)strlen(key) + 3, fp) || strncmp(k, key, strlen(key)) != 0) {
			free(k);
			return 0;
		}
		free(k);
	}
	while (got < n && fscanf(fp, "%lf", &v[got]) == 1)
		got++;
	return got == n;
}

int ps_cache_get(const char *dir, const char *key, double *v, int n)
{
	char path[4096];
	FILE *fp;
	int ok;
	entry_path(dir, key, path, sizeof path);
	fp = fopen(path, "r");
	if (!fp)
		return 0;
	ok = entry_parse(fp, key, v, n);
	fclose(fp);
	return ok;
}

int ps_cache_parse(const char *text, size_t len, const char *key, double *v, int n)
{
	FILE *fp;
	int ok;
	if (len == 0)
		return 0;
	fp = fmemopen((void *)(uintptr_t)text, len, "r");
	if (!fp)
		return 0;
	ok = entry_parse(fp, key, v, n);
	fclose(fp);
	return ok;
}

static int mkdir_p(const char *dir)
{
	char tmp[4096];
	size_t n = strlen(dir);
	if (n >= sizeof tmp)
		return -1;
	memcpy(tmp, dir, n + 1);
	for (char *p = tmp + 1; *p; p++)
		if (*p == '/') {
			*p = '\0';
			if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
				return -1;
			*p = '/';
		}
	return mkdir(tmp, 0755) != 0 && errno != EEXIST ? -1 : 0;
}

int ps_cache_put(const char *dir, const char *key, const double *v, int n, struct ps_err *e)
{
	char path[4096], tmp[4200], *slash;
	FILE *fp;
	entry_path(dir, key, path, sizeof path);
	slash = strrchr(path, '/');
	*slash = '\0';
	if (mkdir_p(path) != 0)
		return ps_errsys(e, "%s", path);
	*slash = '/';
	snprintf(tmp, sizeof tmp, "%s.%ld", path, (long)getpid());
	fp = fopen(tmp, "w");
	if (!fp)
		return ps_errsys(e, "%s", tmp);
	fprintf(fp, "psscene-cache 1\n%s\n", key);
	for (int i = 0; i < n; i++)
		fprintf(fp, "%.17g\n", v[i]);
	if (fclose(fp) != 0 || rename(tmp, path) != 0) {
		int rc = ps_errsys(e, "%s", path);
		unlink(tmp);
		return rc;
	}
	return 0;
}
