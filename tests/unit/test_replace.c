/* SPDX-License-Identifier: ISC */
/* The durable replace: the file is fsync'd before the rename and the
 * directory after it, and a failure at any step leaves the old file whole,
 * no temporary behind and the step's errno. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "replace.h"

enum call { OPEN_FILE, OPEN_DIR, WRITE, FSYNC_FILE, FSYNC_DIR, CLOSE, RENAME, UNLINK };

/* the calls made, in order; fail_at: the index of the call that fails */
static struct {
	enum call log[64];
	int n, fail_at, dir_fd;
} rec;

/* record a call: 1 when it is the one to fail */
static int record(enum call c)
{
	assert_true(rec.n < 64);
	rec.log[rec.n] = c;
	if (rec.n++ == rec.fail_at) {
		errno = EDQUOT;   /* unlike anything the real calls would say here */
		return 1;
	}
	return 0;
}

static int fake_open(const char *path, int flags, mode_t mode)
{
	int fd;
	if (record(flags & O_DIRECTORY ? OPEN_DIR : OPEN_FILE))
		return -1;
	fd = open(path, flags, mode);
	if (flags & O_DIRECTORY)
		rec.dir_fd = fd;
	return fd;
}

static ssize_t fake_write(int fd, const void *buf, size_t n)
{
	/* a short write first: the helper must go on with the rest */
	if (record(WRITE))
		return -1;
	return write(fd, buf, n > 3 ? 3 : n);
}

static int fake_fsync(int fd)
{
	return record(fd == rec.dir_fd ? FSYNC_DIR : FSYNC_FILE) ? -1 : fsync(fd);
}

static int fake_close(int fd)
{
	int failed = record(CLOSE);
	close(fd);   /* a failed close still frees the descriptor */
	if (fd == rec.dir_fd)
		rec.dir_fd = -1;
	return failed ? -1 : 0;
}

static int fake_rename(const char *from, const char *to)
{
	return record(RENAME) ? -1 : rename(from, to);
}

static int fake_unlink(const char *path)
{
	record(UNLINK);
	return unlink(path);
}

static const struct ps_replace_ops fakes = {
	.open = fake_open,
	.write = fake_write,
	.fsync = fake_fsync,
	.close = fake_close,
	.rename = fake_rename,
	.unlink = fake_unlink,
};

static char dir[64], path[128];

static void start(int fail_at)
{
	memset(&rec, 0, sizeof rec);
	rec.fail_at = fail_at;
	rec.dir_fd = -1;
	snprintf(dir, sizeof dir, "/tmp/psreplaceXXXXXX");
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof path, "%s/state", dir);
	FILE *fp = fopen(path, "w");
	assert_non_null(fp);
	fputs("old contents\n", fp);
	assert_int_equal(fclose(fp), 0);
}

static void read_back(char *buf, size_t n)
{
	FILE *fp = fopen(path, "r");
	assert_non_null(fp);
	buf[fread(buf, 1, n - 1, fp)] = '\0';
	fclose(fp);
}

/* the entries in dir, and clean it away */
static int entries_then_remove(void)
{
	DIR *d = opendir(dir);
	struct dirent *de;
	int n = 0;
	char p[384];
	assert_non_null(d);
	while ((de = readdir(d)))
		if (strcmp(de->d_name, ".") != 0 && strcmp(de->d_name, "..") != 0) {
			n++;
			snprintf(p, sizeof p, "%s/%s", dir, de->d_name);
			unlink(p);
		}
	closedir(d);
	rmdir(dir);
	return n;
}

static int first(enum call c)
{
	for (int i = 0; i < rec.n; i++)
		if (rec.log[i] == c)
			return i;
	return -1;
}

static void file_synced_before_rename_dir_after(void **state)
{
	struct ps_err e;
	char buf[64];
	(void)state;
	start(-1);
	assert_int_equal(ps_replace_file_ops(&fakes, path, 0644, "new contents\n", 13, &e), 0);
	read_back(buf, sizeof buf);
	assert_string_equal(buf, "new contents\n");
	assert_true(first(WRITE) >= 0);
	assert_true(first(FSYNC_FILE) > first(WRITE));
	assert_true(first(RENAME) > first(FSYNC_FILE));
	assert_true(first(FSYNC_DIR) > first(RENAME));
	assert_true(first(OPEN_DIR) > first(RENAME));
	assert_int_equal(first(UNLINK), -1);
	assert_int_equal(entries_then_remove(), 1);
	assert_int_equal(rec.dir_fd, -1);   /* the directory closed too */
}

/* every call before the rename made to fail: the old file is whole, no
 * temporary is left, the error names the step's errno */
static void each_failure_before_rename_keeps_old(void **state)
{
	struct ps_err e;
	char buf[64];
	int steps;
	(void)state;
	start(-1);
	assert_int_equal(ps_replace_file_ops(&fakes, path, 0644, "new contents\n", 13, &e), 0);
	steps = first(RENAME);
	entries_then_remove();
	for (int k = 0; k <= steps; k++) {
		start(k);
		errno = 0;
		assert_int_equal(ps_replace_file_ops(&fakes, path, 0644, "new contents\n", 13, &e), -1);
		assert_int_equal(errno, EDQUOT);
		assert_int_equal(e.sys_errno, EDQUOT);
		assert_non_null(strstr(e.msg, strerror(EDQUOT)));
		read_back(buf, sizeof buf);
		assert_string_equal(buf, "old contents\n");
		assert_int_equal(entries_then_remove(), 1);
	}
}

/* after the rename the new file is in place; a failure to make that last
 * is still reported */
static void each_failure_after_rename_is_reported(void **state)
{
	struct ps_err e;
	char buf[64];
	int steps, renamed;
	(void)state;
	start(-1);
	assert_int_equal(ps_replace_file_ops(&fakes, path, 0644, "new contents\n", 13, &e), 0);
	renamed = first(RENAME);
	steps = rec.n;
	entries_then_remove();
	for (int k = renamed + 1; k < steps; k++) {
		start(k);
		assert_int_equal(ps_replace_file_ops(&fakes, path, 0644, "new contents\n", 13, &e), -1);
		assert_int_equal(e.sys_errno, EDQUOT);
		read_back(buf, sizeof buf);
		assert_string_equal(buf, "new contents\n");
		assert_int_equal(entries_then_remove(), 1);
	}
}

/* a temporary another program wrote: fsync'd, renamed, directory fsync'd;
 * each failure before the rename removes it and keeps the old file */
static void put_rendered(char *tmp, size_t n)
{
	snprintf(tmp, n, "%s.rendering", path);
	FILE *fp = fopen(tmp, "w");
	assert_non_null(fp);
	fputs("rendered\n", fp);
	assert_int_equal(fclose(fp), 0);
}

static void install_orders_and_cleans(void **state)
{
	struct ps_err e;
	char tmp[160], buf[64];
	int steps, renamed;
	(void)state;
	start(-1);
	put_rendered(tmp, sizeof tmp);
	assert_int_equal(ps_replace_install_ops(&fakes, tmp, path, &e), 0);
	assert_true(first(FSYNC_FILE) >= 0);
	assert_true(first(FSYNC_FILE) < first(RENAME));
	assert_true(first(RENAME) < first(FSYNC_DIR));
	renamed = first(RENAME);
	steps = rec.n;
	read_back(buf, sizeof buf);
	assert_string_equal(buf, "rendered\n");
	assert_int_equal(entries_then_remove(), 1);
	for (int k = 0; k < steps; k++) {
		start(k);
		put_rendered(tmp, sizeof tmp);
		assert_int_equal(ps_replace_install_ops(&fakes, tmp, path, &e), -1);
		assert_int_equal(e.sys_errno, EDQUOT);
		read_back(buf, sizeof buf);
		assert_string_equal(buf, k <= renamed ? "old contents\n" : "rendered\n");
		assert_int_equal(entries_then_remove(), 1);
	}
}

static void mem_writer_puts_text_in_place(void **state)
{
	struct ps_replace_mem m;
	struct ps_err e;
	char buf[64];
	FILE *fp;
	(void)state;
	start(-1);
	assert_non_null(fp = ps_replace_mem_open(&m, &e));
	fprintf(fp, "n %d\n", 42);
	assert_int_equal(ps_replace_mem_commit(&m, path, 0644, &e), 0);
	read_back(buf, sizeof buf);
	assert_string_equal(buf, "n 42\n");
	assert_int_equal(entries_then_remove(), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(file_synced_before_rename_dir_after),
		cmocka_unit_test(each_failure_before_rename_keeps_old),
		cmocka_unit_test(each_failure_after_rename_is_reported),
		cmocka_unit_test(install_orders_and_cleans),
		cmocka_unit_test(mem_writer_puts_text_in_place),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
