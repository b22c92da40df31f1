/* SPDX-License-Identifier: ISC */
/* See dali_preload.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dali_preload.h"

#define PRELOAD "libumockdev-preload.so.0"

/* LD_PRELOAD naming a library is not proof it loaded: ld.so only warns */
static int preload_mapped(void)
{
	FILE *fp = fopen("/proc/self/maps", "r");
	char line[512];
	int found = 0;
	if (!fp)
		return 0;
	while (!found && fgets(line, sizeof line, fp))
		found = strstr(line, "libumockdev-preload") != NULL;
	fclose(fp);
	return found;
}

void ps_test_need_umockdev(char **argv)
{
	const char *pre = getenv("LD_PRELOAD");
	char buf[4096];
	if (preload_mapped())
		return;
	if (getenv("PS_TEST_REEXEC")) {
		printf("%s could not be preloaded (install umockdev)\n", PRELOAD);
		exit(77);
	}
	/* the preload must come first; under ASan the runtime wants to be first
	 * too, which its link-order check would refuse (doc/emulation.md pitfall 10) */
	snprintf(buf, sizeof buf, "%s%s%s", PRELOAD, pre && *pre ? ":" : "", pre ? pre : "");
	setenv("LD_PRELOAD", buf, 1);
	pre = getenv("ASAN_OPTIONS");
	snprintf(buf, sizeof buf, "%s%sverify_asan_link_order=0", pre ? pre : "", pre && *pre ? ":" : "");
	setenv("ASAN_OPTIONS", buf, 1);
	setenv("PS_TEST_REEXEC", "1", 1);
	execv("/proc/self/exe", argv);
	printf("cannot re-execute %s under %s\n", argv[0], PRELOAD);
	exit(77);
}
