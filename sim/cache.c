/* SPDX-License-Identifier: ISC */
#include "cache.h"
#include "replace.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <nettle/sha2.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
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

int ps_cache_hash_file(const char *path, char hex[65], struct ps_err *e)
{
	struct sha256_ctx ctx;
	uint8_t buf[65536], d[SHA256_DIGEST_SIZE];
	size_t n;
	FILE *fp = fopen(path, "rb");
	if (!fp)
		return ps_err_sys(e, "%s", path);
	sha256_init(&ctx);
	while ((n = fread(buf, 1, sizeof buf, fp)) > 0)
		sha256_update(&ctx, n, buf);
	if (ferror(fp)) {
		int rc = ps_err_sys(e, "%s: read error", path);
		fclose(fp);
		return rc;
	}
	fclose(fp);
	sha256_digest(&ctx, sizeof d, d);
	to_hex(d, hex);
	return 0;
}

void ps_cache_hash_string(const char *s, char hex[65])
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
	ps_cache_hash_string(key, h);
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
	char path[4096], *slash;
	struct ps_replace_mem m;
	FILE *fp;
	entry_path(dir, key, path, sizeof path);
	slash = strrchr(path, '/');
	*slash = '\0';
	if (mkdir_p(path) != 0)
		return ps_err_sys(e, "%s", path);
	*slash = '/';
	if (!(fp = ps_replace_mem_open(&m, e)))
		return -1;
	fprintf(fp, "psscene-cache 1\n%s\n", key);
	for (int i = 0; i < n; i++)
		fprintf(fp, "%.17g\n", v[i]);
	return ps_replace_mem_commit(&m, path, 0644, e);
}

/* ---- binary entries ------------------------------------------------------- */

static const char blob_magic[8] = { 'P', 'S', 'C', 'B', 'L', 'O', 'B', '2' };
static const char blob_magic_old[8] = { 'P', 'S', 'C', 'B', 'L', 'O', 'B', '1' };

/* The payload's checksum: a 64-bit sum that catches a truncated, altered or
 * shuffled entry (not an adversary: the cache is the user's own).  Four
 * lanes take the payload's 64-bit words in turn, each lane
 * rotl(lane ^ word, 29) x an odd constant (a bijection of the word, so
 * changing any one word always changes its lane), the tail's bytes
 * zero-padded to a word; the lanes and the length are then mixed into one
 * word.  It takes about a third of the time a SHA-256 does. */
struct sum64 {
	uint64_t lane[4];
	uint8_t buf[32];
	size_t nbuf;
	uint64_t total;
};

static const uint64_t sum_k[4] = { 0x9e3779b97f4a7c15ull, 0xc2b2ae3d27d4eb4full, 0x165667b19e3779f9ull,
                                   0xd6e8feb86659fd93ull };

static uint64_t rotl64(uint64_t x, int r)
{
	return x << r | x >> (64 - r);
}

static void sum_init(struct sum64 *c)
{
	for (int i = 0; i < 4; i++)
		c->lane[i] = sum_k[3 - i];
	c->nbuf = 0;
	c->total = 0;
}

static void sum_block(uint64_t lane[4], const uint8_t *p)
{
	for (int i = 0; i < 4; i++) {
		uint64_t v;
		memcpy(&v, p + 8 * i, 8);
		lane[i] = rotl64(lane[i] ^ v, 29) * sum_k[i];
	}
}

static void sum_update(struct sum64 *c, const void *data, size_t n)
{
	const uint8_t *p = data;
	uint64_t lane[4];
	c->total += n;
	if (c->nbuf) {
		size_t k = 32 - c->nbuf < n ? 32 - c->nbuf : n;
		memcpy(c->buf + c->nbuf, p, k);
		c->nbuf += k;
		p += k;
		n -= k;
		if (c->nbuf < 32)
			return;
		sum_block(c->lane, c->buf);
		c->nbuf = 0;
	}
	memcpy(lane, c->lane, sizeof lane);
	for (; n >= 32; p += 32, n -= 32)
		sum_block(lane, p);
	memcpy(c->lane, lane, sizeof lane);
	memcpy(c->buf, p, n);
	c->nbuf = n;
}

static uint64_t sum_mix(uint64_t x)
{
	x ^= x >> 31;
	x *= 0xbf58476d1ce4e5b9ull;
	x ^= x >> 29;
	x *= 0x94d049bb133111ebull;
	return x ^ x >> 32;
}

static uint64_t sum_final(struct sum64 *c)
{
	uint64_t h = c->total;
	if (c->nbuf) {
		memset(c->buf + c->nbuf, 0, 32 - c->nbuf);
		sum_block(c->lane, c->buf);
	}
	for (int i = 0; i < 4; i++)
		h = sum_mix(h ^ c->lane[i]) * sum_k[i];
	return sum_mix(h);
}

void ps_cache_default_dir(char *buf, size_t len)
{
	const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
	if (x && *x)
		snprintf(buf, len, "%s/psensd", x);
	else
		snprintf(buf, len, "%s/.cache/psensd", home && *home ? home : "/tmp");
}

size_t ps_cache_max_bytes(void)
{
	const char *s = getenv("PSENSD_CACHE_MAX");
	char *end;
	double v;
	if (!s || !*s)
		return PS_CACHE_MAX_DEFAULT;
	v = strtod(s, &end);
	if (end == s || !(v >= 0))
		return PS_CACHE_MAX_DEFAULT;
	switch (*end) {
	case 'k': case 'K': v *= 1024; end++; break;
	case 'm': case 'M': v *= 1024 * 1024; end++; break;
	case 'g': case 'G': v *= 1024.0 * 1024 * 1024; end++; break;
	}
	if (*end || v > 1e18)
		return PS_CACHE_MAX_DEFAULT;
	return (size_t)v;
}

static int hex_ok(const char *hex)
{
	if (strlen(hex) != 64)
		return 0;
	for (int i = 0; i < 64; i++)
		if (!strchr("0123456789abcdef", hex[i]))
			return 0;
	return 1;
}

static void from_hex(const char *hex, uint8_t out[32])
{
	for (int i = 0; i < 32; i++) {
		int hi = hex[2 * i] <= '9' ? hex[2 * i] - '0' : hex[2 * i] - 'a' + 10;
		int lo = hex[2 * i + 1] <= '9' ? hex[2 * i + 1] - '0' : hex[2 * i + 1] - 'a' + 10;
		out[i] = (uint8_t)(hi << 4 | lo);
	}
}

static void blob_path(const char *dir, const char *hexkey, char *out, size_t len)
{
	snprintf(out, len, "%s/blobs/%.2s/%s", dir, hexkey, hexkey + 2);
}

static void put_le64(uint8_t *p, uint64_t v)
{
	for (int i = 0; i < 8; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

static uint64_t get_le64(const uint8_t *p)
{
	uint64_t v = 0;
	for (int i = 7; i >= 0; i--)
		v = v << 8 | p[i];
	return v;
}

void ps_cache_blob_release(struct ps_cache_blob *b)
{
	if (b && b->map)
		munmap(b->map, b->maplen);
	if (b)
		memset(b, 0, sizeof *b);
}

/* drop: file is a shared read-only map of the entry; the pages hashed leave
 * the resident set when the hash is done (they stay in the page cache).
 * Once for the whole entry, not a chunk at a time: each madvise on a shared
 * map is a TLB shoot-down on every core. */
static int blob_check(const void *file, size_t len, const char *hexkey, const char *name,
                      int drop, struct ps_err *e)
{
	const uint8_t *h = file;
	uint8_t key[32];
	struct sum64 ctx;
	uint64_t plen;
	if (!hex_ok(hexkey))
		return ps_err_set(e, PS_EINVAL, "cache key '%.80s' is not 64 hex digits", hexkey);
	if (len < PS_CACHE_BLOB_HEADER)
		return ps_err_set(e, PS_EFORMAT, "%s: byte %zu: shorter than its %d-byte header: cache "
		                  "entry removed", name, len, PS_CACHE_BLOB_HEADER);
	if (memcmp(h, blob_magic_old, sizeof blob_magic_old) == 0)
		return ps_err_set(e, PS_EFORMAT, "%s: byte 0: an entry of an older format: removed", name);
	if (memcmp(h, blob_magic, sizeof blob_magic) != 0)
		return ps_err_set(e, PS_EFORMAT, "%s: byte 0: not a cache entry (bad magic): removed", name);
	from_hex(hexkey, key);
	if (memcmp(h + 16, key, 32) != 0)
		return ps_err_set(e, PS_EFORMAT, "%s: byte 16: the entry is for another key: removed", name);
	plen = get_le64(h + 8);
	if (plen != (uint64_t)(len - PS_CACHE_BLOB_HEADER))
		return ps_err_set(e, PS_EFORMAT, "%s: byte %zu: %s (the header says %llu payload bytes): "
		                  "cache entry removed", name, len,
		                  plen > (uint64_t)(len - PS_CACHE_BLOB_HEADER) ? "truncated" : "overlong",
		                  (unsigned long long)plen);
	sum_init(&ctx);
	{
		const size_t chunk = (size_t)4 << 20;   /* a multiple of any page size */
		size_t at = 0;
		while (at < len) {
			size_t n = len - at < chunk ? len - at : chunk;
			if (at == 0) {   /* the header is not hashed */
				sum_update(&ctx, h + PS_CACHE_BLOB_HEADER, n - PS_CACHE_BLOB_HEADER);
			} else {
				sum_update(&ctx, h + at, n);
			}
			at += n;
		}
	}
	if (drop)
		madvise((void *)(uintptr_t)h, len, MADV_DONTNEED);
	if (sum_final(&ctx) != get_le64(h + 48))
		return ps_err_set(e, PS_EFORMAT, "%s: checksum mismatch: cache entry removed", name);
	for (int i = 56; i < PS_CACHE_BLOB_HEADER; i++)
		if (h[i])
			return ps_err_set(e, PS_EFORMAT, "%s: byte %d: reserved header byte not zero: "
			                  "cache entry removed", name, i);
	return 0;
}

int ps_cache_blob_check(const void *file, size_t len, const char *hexkey, const char *name,
                        struct ps_err *e)
{
	return blob_check(file, len, hexkey, name, 0, e);
}

int ps_cache_blob_get(const char *dir, const char *hexkey, struct ps_cache_blob *b,
                      struct ps_err *e)
{
	char path[4096];
	struct stat st;
	void *map;
	int fd;
	memset(b, 0, sizeof *b);
	if (!hex_ok(hexkey))
		return ps_err_set(e, PS_EINVAL, "cache key '%.80s' is not 64 hex digits", hexkey);
	blob_path(dir, hexkey, path, sizeof path);
	fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0)
		return errno == ENOENT || errno == ENOTDIR ? 0 : ps_err_sys(e, "%s", path);
	if (fstat(fd, &st) != 0) {
		int rc = ps_err_sys(e, "%s", path);
		close(fd);
		return rc;
	}
	if (!S_ISREG(st.st_mode) || st.st_size < PS_CACHE_BLOB_HEADER) {
		close(fd);
		unlink(path);
		return ps_err_set(e, PS_EFORMAT, "%s: byte %lld: shorter than its %d-byte header: cache "
		                  "entry removed", path, (long long)st.st_size, PS_CACHE_BLOB_HEADER);
	}
	map = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_SHARED, fd, 0);
	if (map == MAP_FAILED) {
		int rc = ps_err_sys(e, "%s: mmap", path);
		close(fd);
		return rc;
	}
	/* a hit: the entry was used now (least-recently-used eviction) */
	futimens(fd, NULL);
	close(fd);
	if (blob_check(map, (size_t)st.st_size, hexkey, path, 1, e) != 0) {
		munmap(map, (size_t)st.st_size);
		unlink(path);
		return -1;
	}
	b->map = map;
	b->maplen = (size_t)st.st_size;
	b->data = (const uint8_t *)map + PS_CACHE_BLOB_HEADER;
	b->len = (size_t)st.st_size - PS_CACHE_BLOB_HEADER;
	return 1;
}

static int write_all(int fd, const void *p, size_t n)
{
	const uint8_t *c = p;
	while (n > 0) {
		ssize_t k = write(fd, c, n);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0)
			return -1;
		c += k;
		n -= (size_t)k;
	}
	return 0;
}

/* Evict oldest-used entries until at most max_bytes remain, keeping keep
 * (may be NULL); returns the number removed (-1 when the lock fails). */
static long ps_cache_blob_evict(const char *dir, size_t max_bytes, const char *keep);

int ps_cache_blob_put(const char *dir, const char *hexkey, int n, const void *const *ptr,
                      const size_t *len, size_t max_bytes, struct ps_err *e)
{
	static unsigned long counter;   /* temp names: pid + a per-call number */
	char path[4096], tmp[4200], *slash;
	uint8_t h[PS_CACHE_BLOB_HEADER];
	struct sum64 ctx;
	uint64_t total = 0;
	unsigned long k;
	int fd;
	if (!hex_ok(hexkey))
		return ps_err_set(e, PS_EINVAL, "cache key '%.80s' is not 64 hex digits", hexkey);
	blob_path(dir, hexkey, path, sizeof path);
	slash = strrchr(path, '/');
	*slash = '\0';
	if (mkdir_p(path) != 0)
		return ps_err_sys(e, "%s", path);
	*slash = '/';
	memset(h, 0, sizeof h);
	memcpy(h, blob_magic, sizeof blob_magic);
	from_hex(hexkey, h + 16);
	sum_init(&ctx);
	for (int i = 0; i < n; i++) {
		sum_update(&ctx, ptr[i], len[i]);
		total += len[i];
	}
	put_le64(h + 8, total);
	put_le64(h + 48, sum_final(&ctx));
	k = __atomic_add_fetch(&counter, 1, __ATOMIC_RELAXED);
	snprintf(tmp, sizeof tmp, "%s.tmp.%ld.%lu", path, (long)getpid(), k);
	fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
	if (fd < 0)
		return ps_err_sys(e, "%s", tmp);
	if (write_all(fd, h, sizeof h) != 0)
		goto fail;
	for (int i = 0; i < n; i++)
		if (write_all(fd, ptr[i], len[i]) != 0)
			goto fail;
	if (close(fd) != 0) {
		fd = -1;
		goto fail;
	}
	fd = -1;
	if (ps_replace_install(tmp, path, e) != 0)
		return -1;
	if (max_bytes > 0)
		ps_cache_blob_evict(dir, max_bytes, hexkey);
	return 0;
fail:
	{
		int rc = ps_err_sys(e, "%s", tmp);
		if (fd >= 0)
			close(fd);
		unlink(tmp);
		return rc;
	}
}

/* ---- an entry written in place ---------------------------------------- */

int ps_cache_blob_create(const char *dir, const char *hexkey, size_t len, struct ps_cache_blob_out *o,
                         struct ps_err *e)
{
	static unsigned long counter;
	char *slash;
	size_t total = PS_CACHE_BLOB_HEADER + len;
	unsigned long k;
	memset(o, 0, sizeof *o);
	o->fd = -1;
	if (!hex_ok(hexkey))
		return ps_err_set(e, PS_EINVAL, "cache key '%.80s' is not 64 hex digits", hexkey);
	blob_path(dir, hexkey, o->path, sizeof o->path);
	slash = strrchr(o->path, '/');
	*slash = '\0';
	if (mkdir_p(o->path) != 0)
		return ps_err_sys(e, "%s", o->path);
	*slash = '/';
	k = __atomic_add_fetch(&counter, 1, __ATOMIC_RELAXED);
	snprintf(o->tmp, sizeof o->tmp, "%s.tmp.%ld.m%lu", o->path, (long)getpid(), k);
	o->fd = open(o->tmp, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
	if (o->fd < 0)
		return ps_err_sys(e, "%s", o->tmp);
	/* the blocks reserved before the first store through the map: a full
	 * disk is this error, never a SIGBUS in the middle of the fill; a file
	 * system without fallocate says so here too (not posix_fallocate,
	 * which would write the zeros itself) */
	if (fallocate(o->fd, 0, 0, (off_t)total) != 0)
		goto fail;
	o->map = mmap(NULL, total, PROT_READ | PROT_WRITE, MAP_SHARED, o->fd, 0);
	if (o->map == MAP_FAILED) {
		o->map = NULL;
		goto fail;
	}
#ifdef MADV_HUGEPAGE
	madvise(o->map, total, MADV_HUGEPAGE);
#endif
	o->maplen = total;
	o->len = len;
	o->payload = (uint8_t *)o->map + PS_CACHE_BLOB_HEADER;
	memcpy(o->hex, hexkey, 64);
	o->hex[64] = '\0';
	return 0;
fail:
	{
		int rc = ps_err_sys(e, "%s", o->tmp);
		close(o->fd);
		unlink(o->tmp);
		o->fd = -1;
		return rc;
	}
}

int ps_cache_blob_commit(struct ps_cache_blob_out *o, const char *dir, size_t max_bytes,
                         struct ps_err *e)
{
	uint8_t *h = o->map;
	struct sum64 ctx;
	int rc = 0;
	memset(h, 0, PS_CACHE_BLOB_HEADER);
	sum_init(&ctx);
	sum_update(&ctx, o->payload, o->len);
	put_le64(h + 48, sum_final(&ctx));
	put_le64(h + 8, o->len);
	from_hex(o->hex, h + 16);
	/* the magic last: a header without it is never a whole entry */
	memcpy(h, blob_magic, sizeof blob_magic);
	if (close(o->fd) != 0) {
		rc = ps_err_sys(e, "%s", o->tmp);
		unlink(o->tmp);
	} else if (ps_replace_install(o->tmp, o->path, e) != 0) {
		rc = -1;
	} else if (max_bytes > 0) {
		ps_cache_blob_evict(dir, max_bytes, o->hex);
	}
	o->fd = -1;
	return rc;
}

void ps_cache_blob_abort(struct ps_cache_blob_out *o)
{
	if (o->fd >= 0) {
		close(o->fd);
		unlink(o->tmp);
	}
	o->fd = -1;
}

struct blob_file {
	char path[4200];
	off_t size;
	struct timespec used;
	int keep;
};

static int by_use(const void *a, const void *b)
{
	const struct blob_file *x = a, *y = b;
	if (x->used.tv_sec != y->used.tv_sec)
		return x->used.tv_sec < y->used.tv_sec ? -1 : 1;
	if (x->used.tv_nsec != y->used.tv_nsec)
		return x->used.tv_nsec < y->used.tv_nsec ? -1 : 1;
	return 0;
}

static long ps_cache_blob_evict(const char *dir, size_t max_bytes, const char *keep)
{
	char top[4096], lock[4200];
	struct blob_file *f = NULL;
	size_t nf = 0, cap = 0;
	uint64_t total = 0;
	long removed = 0;
	time_t now = time(NULL);
	DIR *d;
	struct dirent *de;
	int lfd;
	snprintf(top, sizeof top, "%s/blobs", dir);
	snprintf(lock, sizeof lock, "%s/.lock", top);
	lfd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
	if (lfd < 0 || flock(lfd, LOCK_EX) != 0) {
		if (lfd >= 0)
			close(lfd);
		return -1;
	}
	d = opendir(top);
	while (d && (de = readdir(d))) {
		char sub[4400];
		DIR *d2;
		struct dirent *de2;
		if (strlen(de->d_name) != 2 || !isxdigit((unsigned char)de->d_name[0]))
			continue;
		snprintf(sub, sizeof sub, "%s/%s", top, de->d_name);
		d2 = opendir(sub);
		while (d2 && (de2 = readdir(d2))) {
			struct stat st;
			char p[4200];
			if (de2->d_name[0] == '.')
				continue;
			snprintf(p, sizeof p, "%.4000s/%.190s", sub, de2->d_name);
			if (stat(p, &st) != 0 || !S_ISREG(st.st_mode))
				continue;
			if (strstr(de2->d_name, ".tmp.")) {
				/* a writer that died an hour ago left it */
				if (now - st.st_mtime > 3600 && unlink(p) == 0)
					removed++;
				continue;
			}
			if (nf == cap) {
				size_t nc = cap ? 2 * cap : 64;
				struct blob_file *nfp = realloc(f, nc * sizeof *nfp);
				if (!nfp)
					break;
				f = nfp;
				cap = nc;
			}
			snprintf(f[nf].path, sizeof f[nf].path, "%s", p);
			f[nf].size = st.st_size;
			f[nf].used = st.st_mtim;
			f[nf].keep = keep && strlen(de2->d_name) == 62 &&
			             strncmp(keep, de->d_name, 2) == 0 && strcmp(keep + 2, de2->d_name) == 0;
			total += (uint64_t)st.st_size;
			nf++;
		}
		if (d2)
			closedir(d2);
	}
	if (d)
		closedir(d);
	if (total > max_bytes && nf > 0) {
		qsort(f, nf, sizeof *f, by_use);
		for (size_t i = 0; i < nf && total > max_bytes; i++) {
			if (f[i].keep)
				continue;
			if (unlink(f[i].path) == 0) {
				total -= (uint64_t)f[i].size;
				removed++;
			}
		}
	}
	free(f);
	flock(lfd, LOCK_UN);
	close(lfd);
	return removed;
}
