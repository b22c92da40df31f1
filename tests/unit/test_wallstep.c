/* SPDX-License-Identifier: ISC */
/* Steps of the wall clock (daemon/wallstep.c), injected through the tests'
 * offset file: a step is reported with its size once, then taken as the
 * new reference; a change within the threshold is none; the wall reading
 * carries the offset; a file without a number means no offset. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "wallstep.h"

static char path[] = "/tmp/pswallXXXXXX";

static void offset(const char *text)
{
	FILE *fp = fopen(path, "w");
	assert_non_null(fp);
	fputs(text, fp);
	fclose(fp);
}

static void steps(void **state)
{
	struct psd_wallstep w;
	(void)state;
	offset("0\n");
	psd_wallstep_init(&w, 1.0);
	assert_true(psd_wallstep_check(&w) == 0);
	offset("5\n");
	assert_float_equal(psd_wallstep_check(&w), 5.0, 0.01);
	assert_true(psd_wallstep_check(&w) == 0);       /* reported once */
	offset("5.5\n");
	assert_true(psd_wallstep_check(&w) == 0);       /* half a second: within the threshold */
	offset("3\n");
	assert_float_equal(psd_wallstep_check(&w), -2.0, 0.01);   /* from the reference, 5 */
	assert_float_equal(psd_wallstep_wall(), (double)time(NULL) + 3, 1.5);
	offset("soon\n");
	assert_float_equal(psd_wallstep_check(&w), -3.0, 0.01);   /* no number: no offset */
	assert_float_equal(psd_wallstep_wall(), (double)time(NULL), 1.5);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(steps),
	};
	int fd = mkstemp(path), rc;
	if (fd < 0)
		return 1;
	close(fd);
	setenv("PSENSD_TEST_WALL_OFFSET", path, 1);
	rc = cmocka_run_group_tests(tests, NULL, NULL);
	unlink(path);
	return rc;
}
