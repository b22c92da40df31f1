/* SPDX-License-Identifier: ISC */
/* The weight cache (sim/cache.c blobs, sim/weights/wcache.c): a stored map comes
 * back bit for bit; the key is the content (the same table under another
 * file name hits, another rotation misses); a truncated entry, a flipped
 * byte anywhere, two payload words swapped, an entry of the older format
 * (SHA-256 in its header), or a checksummed payload that is not a map are
 * rebuilt and never trusted; a cache that cannot be written works uncached; eviction
 * removes the least recently used first and keeps the bound; processes
 * sharing one cache at once all get the exact map. */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "cache.h"
#include "cellmap.h"
#include "sensor.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

enum { N = 48 };

static char dir[64];

static int rm_rf(const char *path)
{
	char cmd[256];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", path);
	return system(cmd);
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof dir, "/tmp/test_wcache.XXXXXX");
	return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	return rm_rf(dir) == 0 ? 0 : -1;
}

static const char table[] = "Elevation field 90\n"
                            "degrees 0 90 180 270\n"
                            "0 1 1 1 1\n30 0.9 0.7 0.8 0.6\n60 0.5 0.2 0.4 0.3\n90 0 0 0 0\n";

static void sensor(struct ps_sensor *s, const char *name)
{
	struct ps_err e;
	if (ps_sensor_parse(s, table, sizeof table - 1, name, &e) != 0 ||
	    ps_sensor_set_reading(s, PS_READ_LINEAR, &e) != 0)
		fail_msg("%s", e.msg);
}

static void same_map(const struct ps_weights *a, const struct ps_weights *b)
{
	assert_int_equal(a->nruns, b->nruns);
	assert_int_equal(a->nw, b->nw);
	for (size_t i = 0; i < a->nruns; i++) {
		assert_int_equal(a->runs[i].row, b->runs[i].row);
		assert_int_equal(a->runs[i].x0, b->runs[i].x0);
		assert_int_equal(a->runs[i].n, b->runs[i].n);
		assert_int_equal(a->runs[i].off, b->runs[i].off);
	}
	assert_memory_equal(a->w, b->w, a->nw * sizeof *a->w);
	assert_true(a->solid_angle == b->solid_angle && a->sens_sum == b->sens_sum &&
	            a->coverage == b->coverage && a->sens_full == b->sens_full);
	assert_string_equal(a->key, b->key);
}

static int get(struct ps_weights *w, const struct ps_sensor *s, double rot, const char *cdir,
               size_t max, struct ps_err *warn)
{
	struct ps_view v;
	struct ps_err e;
	int how = -1;
	ps_view_default_fisheye(&v);
	memset(warn, 0, sizeof *warn);
	if (ps_wcache_get(w, &(struct ps_wcache_key){ s, rot, &v, N, N, PS_W_EXACT }, &(struct ps_wcache_dir){ cdir, max }, &how, warn, &e) != 0)
		fail_msg("%s", e.msg);
	return how;
}

/* The map as the builder gives it: the table changes with azimuth, so from
 * the solid angles (sim/weights/cellmap.h). */
static void built(struct ps_weights *w, const struct ps_sensor *s, double rot)
{
	struct ps_view v;
	struct ps_err e;
	struct ps_sensor uni;
	struct ps_weights om;
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_cellmap_fits(s, PS_W_EXACT), PS_CELLMAP_LINEAR);
	if (ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0 ||
	    ps_weights_build_ex(&om, &uni, 0.0, &v, N, N, PS_W_EXACT, PS_WB_COMPACT, &e) != 0 ||
	    ps_cellmap_build(w, s, rot, &v, N, N, &om, &e) != 0)
		fail_msg("%s", e.msg);
	ps_weights_free(&om);
	ps_sensor_free(&uni);
}

/* The entry file of (s, rot). */
static void entry(const struct ps_sensor *s, double rot, const char *cdir, char *path, size_t len)
{
	struct ps_view v;
	char hex[65];
	ps_view_default_fisheye(&v);
	ps_wcache_key_hex(&(struct ps_wcache_key){ s, rot, &v, N, N, PS_W_EXACT }, hex);
	snprintf(path, len, "%s/blobs/%.2s/%s", cdir, hex, hex + 2);
}

/* The files in the folder of sensor s's entry at rotation rot (hidden ones
 * left out): the entry alone, or nothing, and never a temporary file. */
static int files_beside_entry(const struct ps_sensor *s, double rot, const char *cdir)
{
	char path[512], *slash;
	DIR *d;
	struct dirent *de;
	int files = 0;
	entry(s, rot, cdir, path, sizeof path);
	slash = strrchr(path, '/');
	*slash = '\0';
	d = opendir(path);
	assert_non_null(d);
	while ((de = readdir(d)))
		if (de->d_name[0] != '.')
			files++;
	closedir(d);
	return files;
}

static void stored_then_hit_bit_for_bit(void **state)
{
	struct ps_sensor s, s2;
	struct ps_weights ref, w;
	struct ps_err warn;
	char c[128];
	(void)state;
	snprintf(c, sizeof c, "%s/hit", dir);
	sensor(&s, "a.sen");
	sensor(&s2, "another/name.sen");   /* the same table under another name */
	built(&ref, &s, 15);
	assert_int_equal(get(&w, &s, 15, c, 0, &warn), PS_WC_STORED);
	same_map(&w, &ref);
	/* built straight into the new entry's mapping, renamed into place
	 * whole: the entry alone in its directory, no temporary file left */
	assert_non_null(w.map);
	{
		char path[512];
		struct stat st;
		entry(&s, 15, c, path, sizeof path);
		assert_int_equal(stat(path, &st), 0);
		assert_true((size_t)st.st_size == w.maplen);
		assert_int_equal(files_beside_entry(&s, 15, c), 1);
	}
	ps_weights_free(&w);
	assert_int_equal(get(&w, &s, 15, c, 0, &warn), PS_WC_HIT);
	assert_non_null(w.map);
	same_map(&w, &ref);
	ps_weights_free(&w);
	/* content, not file name */
	assert_int_equal(get(&w, &s2, 15, c, 0, &warn), PS_WC_HIT);
	ps_weights_free(&w);
	/* another rotation is another map */
	assert_int_equal(get(&w, &s, 16, c, 0, &warn), PS_WC_STORED);
	ps_weights_free(&w);
	/* no cache: built */
	assert_int_equal(get(&w, &s, 15, NULL, 0, &warn), PS_WC_BUILT);
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
	ps_sensor_free(&s2);
}

/* Corrupt the entry with f, then: a warning naming the entry, the map
 * rebuilt exactly, and the next read a hit again. */
static void corrupt_and_check(const char *c, void (*f)(const char *path, off_t size, long arg),
                              long arg, const char *expect)
{
	struct ps_sensor s;
	struct ps_weights ref, w;
	struct ps_err warn;
	struct stat st;
	char path[512];
	sensor(&s, "a.sen");
	built(&ref, &s, 40);
	{
		int how = get(&w, &s, 40, c, 0, &warn);   /* stored, or there from the last case */
		assert_true(how == PS_WC_STORED || how == PS_WC_HIT);
	}
	ps_weights_free(&w);
	entry(&s, 40, c, path, sizeof path);
	assert_int_equal(stat(path, &st), 0);
	f(path, st.st_size, arg);
	assert_int_equal(get(&w, &s, 40, c, 0, &warn), PS_WC_REBUILT);
	if (!strstr(warn.msg, path) || !strstr(warn.msg, expect))
		fail_msg("warning '%s' should name %s and say '%s'", warn.msg, path, expect);
	same_map(&w, &ref);
	ps_weights_free(&w);
	assert_int_equal(get(&w, &s, 40, c, 0, &warn), PS_WC_HIT);
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
}

static void truncate_to(const char *path, off_t size, long keep)
{
	(void)size;
	assert_int_equal(truncate(path, keep < 0 ? size + keep : keep), 0);
}

static void flip(const char *path, off_t size, long at)
{
	int fd = open(path, O_RDWR);
	uint8_t b;
	off_t pos = at < 0 ? size + at : at;
	assert_true(fd >= 0);
	assert_int_equal(pread(fd, &b, 1, pos), 1);
	b ^= 0x10;
	assert_int_equal(pwrite(fd, &b, 1, pos), 1);
	close(fd);
}

/* two neighbouring 8-byte words of the payload that differ (the last such
 * pair: two weights) swapped */
static void swap_words(const char *path, off_t size, long unused)
{
	int fd = open(path, O_RDWR);
	uint8_t a[8], b[8];
	off_t at = size - 16;
	(void)unused;
	assert_true(fd >= 0);
	for (; at >= 128; at -= 8) {
		assert_int_equal(pread(fd, a, 8, at), 8);
		assert_int_equal(pread(fd, b, 8, at + 8), 8);
		if (memcmp(a, b, 8) != 0)
			break;
	}
	assert_true(at >= 128);
	assert_int_equal(pwrite(fd, b, 8, at), 8);
	assert_int_equal(pwrite(fd, a, 8, at + 8), 8);
	close(fd);
}

/* the older format's magic, "PSCBLOB1" */
static void old_magic(const char *path, off_t size, long unused)
{
	int fd = open(path, O_RDWR);
	(void)size;
	(void)unused;
	assert_true(fd >= 0);
	assert_int_equal(pwrite(fd, "1", 1, 7), 1);
	close(fd);
}

static void truncated_entries_are_rebuilt(void **state)
{
	char c[128];
	(void)state;
	snprintf(c, sizeof c, "%s/trunc", dir);
	corrupt_and_check(c, truncate_to, -8, "truncated");
	corrupt_and_check(c, truncate_to, 100, "shorter than its 128-byte header");
	corrupt_and_check(c, truncate_to, 0, "shorter than its 128-byte header");
	corrupt_and_check(c, truncate_to, 128 + 40, "truncated");
}

static void one_flipped_byte_is_rebuilt(void **state)
{
	/* magic, length, key, checksum, reserved, payload header, a run, the
	 * last weight */
	static const struct {
		long at;
		const char *says;
	} where[] = { { 3, "bad magic" }, { 9, "truncated" }, { 20, "another key" },
	              { 50, "checksum" }, { 100, "reserved" }, { 128 + 5, "checksum" },
	              { 128 + 64 + 4, "checksum" }, { -1, "checksum" } };
	char c[128];
	(void)state;
	snprintf(c, sizeof c, "%s/flip", dir);
	for (size_t i = 0; i < sizeof where / sizeof where[0]; i++)
		corrupt_and_check(c, flip, where[i].at, where[i].says);
	corrupt_and_check(c, swap_words, 0, "checksum");
	corrupt_and_check(c, old_magic, 0, "older format");
}

/* A sound entry (right key, right checksum) whose payload is no map of the
 * size asked: rebuilt, never used. */
static void checksummed_nonsense_is_not_trusted(void **state)
{
	struct ps_sensor s;
	struct ps_weights ref, w;
	struct ps_view v;
	struct ps_err warn, e;
	char c[128], hex[65];
	uint8_t junk[64 + 16 + 8];
	const void *ptr[1] = { junk };
	size_t len[1] = { sizeof junk };
	(void)state;
	snprintf(c, sizeof c, "%s/junk", dir);
	sensor(&s, "a.sen");
	built(&ref, &s, 0);
	ps_view_default_fisheye(&v);
	ps_wcache_key_hex(&(struct ps_wcache_key){ &s, 0, &v, N, N, PS_W_EXACT }, hex);
	memset(junk, 0, sizeof junk);
	{
		uint32_t version = PS_WEIGHTS_ALGO_VERSION;
		int32_t wh[3] = { N, N, PS_W_EXACT };
		uint64_t counts[2] = { 1, 1 };
		int32_t run[4] = { N, 0, 1, 0 };   /* row N: outside */
		memcpy(junk, &version, 4);
		memcpy(junk + 4, wh, sizeof wh);
		memcpy(junk + 16, counts, sizeof counts);
		memcpy(junk + 64, run, sizeof run);
	}
	assert_int_equal(ps_cache_blob_put(c, hex, 1, ptr, len, 0, &e), 0);
	assert_int_equal(get(&w, &s, 0, c, 0, &warn), PS_WC_REBUILT);
	assert_non_null(strstr(warn.msg, "outside"));
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
}

static void unwritable_cache_works_uncached(void **state)
{
	struct ps_sensor s;
	struct ps_weights ref, w;
	struct ps_err warn;
	char c[128];
	FILE *fp;
	(void)state;
	/* a cache "directory" that is a file: nothing can be written under it
	 * (root ignores permissions; tests/system/013 covers a read-only one) */
	snprintf(c, sizeof c, "%s/plainfile", dir);
	fp = fopen(c, "w");
	assert_non_null(fp);
	fclose(fp);
	sensor(&s, "a.sen");
	built(&ref, &s, 5);
	assert_int_equal(get(&w, &s, 5, c, 0, &warn), PS_WC_UNWRITABLE);
	assert_non_null(strstr(warn.msg, c));
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
}

static void least_recently_used_go_first(void **state)
{
	struct ps_sensor s;
	struct ps_weights w;
	struct ps_err warn;
	char c[128], p[5][512];
	struct stat st;
	size_t one;
	(void)state;
	snprintf(c, sizeof c, "%s/lru", dir);
	sensor(&s, "a.sen");
	for (int k = 0; k < 3; k++) {   /* rotations 0, 1, 2: three entries of one size */
		assert_int_equal(get(&w, &s, k, c, 0, &warn), PS_WC_STORED);
		ps_weights_free(&w);
		entry(&s, k, c, p[k], sizeof p[k]);
		/* distinct, known use times: k = 0 oldest */
		{
			struct timespec t[2] = { { 1000000 + k * 10, 0 }, { 1000000 + k * 10, 0 } };
			assert_int_equal(utimensat(AT_FDCWD, p[k], t, 0), 0);
		}
	}
	assert_int_equal(stat(p[0], &st), 0);
	one = (size_t)st.st_size;
	/* using entry 0 makes it the newest */
	assert_int_equal(get(&w, &s, 0, c, 0, &warn), PS_WC_HIT);
	ps_weights_free(&w);
	/* a fourth with room for three: entry 1 (now the oldest used) goes */
	assert_int_equal(get(&w, &s, 3, c, 3 * one, &warn), PS_WC_STORED);
	ps_weights_free(&w);
	entry(&s, 3, c, p[3], sizeof p[3]);
	assert_int_equal(access(p[0], F_OK), 0);
	assert_int_equal(access(p[1], F_OK), -1);
	assert_int_equal(access(p[2], F_OK), 0);
	assert_int_equal(access(p[3], F_OK), 0);
	/* a bound below one entry keeps only the one just written */
	assert_int_equal(get(&w, &s, 4, c, 1, &warn), PS_WC_STORED);
	ps_weights_free(&w);
	entry(&s, 4, c, p[4], sizeof p[4]);
	assert_int_equal(access(p[0], F_OK), -1);
	assert_int_equal(access(p[2], F_OK), -1);
	assert_int_equal(access(p[3], F_OK), -1);
	assert_int_equal(access(p[4], F_OK), 0);
	ps_sensor_free(&s);
}

/* Eight processes at once on one small cache (room for two maps), each
 * asking for the same four maps in its own order, eviction running all the
 * while: every map each gets is the exact one. */
static void concurrent_processes_share_it(void **state)
{
	enum { PROCS = 8, MAPS = 4, ROUNDS = 6 };
	struct ps_sensor s;
	struct ps_weights ref[MAPS];
	char c[128], p0[512];
	struct stat st;
	pid_t pid[PROCS];
	(void)state;
	snprintf(c, sizeof c, "%s/conc", dir);
	sensor(&s, "a.sen");
	for (int k = 0; k < MAPS; k++)
		built(&ref[k], &s, 10.0 * k);
	{
		struct ps_weights w;
		struct ps_err warn;
		get(&w, &s, 0, c, 0, &warn);
		ps_weights_free(&w);
		entry(&s, 0, c, p0, sizeof p0);
		assert_int_equal(stat(p0, &st), 0);
	}
	for (int i = 0; i < PROCS; i++) {
		pid[i] = fork();
		assert_true(pid[i] >= 0);
		if (pid[i] == 0) {
			int bad = 0;
			for (int r = 0; r < ROUNDS; r++)
				for (int k0 = 0; k0 < MAPS; k0++) {
					int k = (k0 + i + r) % MAPS, how;
					struct ps_weights w;
					struct ps_view v;
					struct ps_err e, warn;
					ps_view_default_fisheye(&v);
					if (ps_wcache_get(&w, &(struct ps_wcache_key){ &s, 10.0 * k, &v, N, N, PS_W_EXACT },
					                  &(struct ps_wcache_dir){ c, 2 * (size_t)st.st_size }, &how, &warn, &e) != 0) {
						bad = 1;
						continue;
					}
					if (how == PS_WC_REBUILT || how == PS_WC_UNWRITABLE ||
					    w.nw != ref[k].nw ||
					    memcmp(w.w, ref[k].w, w.nw * sizeof *w.w) != 0)
						bad = 1;
					ps_weights_free(&w);
				}
			_exit(bad);
		}
	}
	for (int i = 0; i < PROCS; i++) {
		int status;
		assert_int_equal(waitpid(pid[i], &status, 0), pid[i]);
		assert_true(WIFEXITED(status));
		assert_int_equal(WEXITSTATUS(status), 0);
	}
	for (int k = 0; k < MAPS; k++)
		ps_weights_free(&ref[k]);
	ps_sensor_free(&s);
}

/* The store by a thread (ps_wcache_get_async): the map is usable at
 * once, the entry is there after ps_wcache_store_finish and gives the same
 * map on the next run; a cache that cannot be written says so at the
 * finish, and the map stays good. */
/* A disk with no room for the entry (a file size limit stands in for it):
 * the entry's blocks are refused before the map is filled in place, so the
 * map is built in memory, the store's error names the cache, and no
 * temporary file or partial entry is left; never a SIGBUS. */
static void full_disk_builds_uncached(void **state)
{
	struct ps_sensor s;
	struct ps_weights ref, w;
	struct ps_err warn;
	struct rlimit old, small;
	char c[128];
	int how;
	void (*was)(int);
	(void)state;
	snprintf(c, sizeof c, "%s/full", dir);
	sensor(&s, "a.sen");
	built(&ref, &s, 7);
	assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
	small = old;
	small.rlim_cur = 4096;   /* below the 48 x 48 map's 18 kB */
	was = signal(SIGXFSZ, SIG_IGN);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
	how = get(&w, &s, 7, c, 0, &warn);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
	signal(SIGXFSZ, was);
	assert_int_equal(how, PS_WC_UNWRITABLE);
	assert_non_null(strstr(warn.msg, c));
	assert_null(w.map);
	same_map(&w, &ref);
	ps_weights_free(&w);
	assert_int_equal(files_beside_entry(&s, 7, c), 0);
	/* with room again: stored in place */
	assert_int_equal(get(&w, &s, 7, c, 0, &warn), PS_WC_STORED);
	assert_non_null(w.map);
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
}

static void stored_by_a_thread(void **state)
{
	struct ps_sensor s;
	struct ps_weights ref, w, again;
	struct ps_view v;
	struct ps_err warn, e;
	struct ps_wcache_store *pending;
	char c[128], path[512], plain[128];
	int how = -1;
	FILE *fp;
	(void)state;
	snprintf(c, sizeof c, "%s/async", dir);
	sensor(&s, "a.sen");
	built(&ref, &s, 25);
	ps_view_default_fisheye(&v);
	memset(&warn, 0, sizeof warn);
	assert_int_equal(ps_wcache_get_async(&w, &(struct ps_wcache_key){ &s, 25, &v, N, N, PS_W_EXACT }, &(struct ps_wcache_dir){ c, 0 }, &how, &warn,
	                                     &pending, &e), 0);
	assert_non_null(pending);
	assert_int_equal(how, PS_WC_STORED);
	same_map(&w, &ref);   /* usable while the store goes on */
	how = -1;
	ps_wcache_store_finish(pending, &how, &warn);
	assert_int_equal(how, PS_WC_STORED);
	entry(&s, 25, c, path, sizeof path);
	assert_int_equal(access(path, F_OK), 0);
	ps_weights_free(&w);
	/* the next run finds it: no store under way */
	assert_int_equal(ps_wcache_get_async(&again, &(struct ps_wcache_key){ &s, 25, &v, N, N, PS_W_EXACT }, &(struct ps_wcache_dir){ c, 0 }, &how,
	                                     &warn, &pending, &e), 0);
	assert_null(pending);
	assert_int_equal(how, PS_WC_HIT);
	same_map(&again, &ref);
	ps_weights_free(&again);
	/* unwritable: told at the finish */
	snprintf(plain, sizeof plain, "%s/plainfile-async", dir);
	fp = fopen(plain, "w");
	assert_non_null(fp);
	fclose(fp);
	assert_int_equal(ps_wcache_get_async(&w, &(struct ps_wcache_key){ &s, 25, &v, N, N, PS_W_EXACT }, &(struct ps_wcache_dir){ plain, 0 }, &how,
	                                     &warn, &pending, &e), 0);
	if (pending)
		ps_wcache_store_finish(pending, &how, &warn);
	assert_int_equal(how, PS_WC_UNWRITABLE);
	assert_true(warn.msg[0] != '\0');
	same_map(&w, &ref);
	ps_weights_free(&w);
	ps_weights_free(&ref);
	ps_sensor_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(stored_then_hit_bit_for_bit),
		cmocka_unit_test(truncated_entries_are_rebuilt),
		cmocka_unit_test(one_flipped_byte_is_rebuilt),
		cmocka_unit_test(checksummed_nonsense_is_not_trusted),
		cmocka_unit_test(unwritable_cache_works_uncached),
		cmocka_unit_test(least_recently_used_go_first),
		cmocka_unit_test(concurrent_processes_share_it),
		cmocka_unit_test(stored_by_a_thread),
		cmocka_unit_test(full_disk_builds_uncached),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
