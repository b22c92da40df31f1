/* SPDX-License-Identifier: ISC */
#include "wallstep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "time.h"

/* The tests' offset: the number in the file PSENSD_TEST_WALL_OFFSET names
 * (0 without the variable, or when the file holds no finite number). */
static double test_offset(void)
{
	const char *path = getenv("PSENSD_TEST_WALL_OFFSET");
	FILE *fp;
	double v = 0;
	if (!path || !*path || !(fp = fopen(path, "re")))
		return 0;
	if (fscanf(fp, "%lf", &v) != 1 || !isfinite(v))
		v = 0;
	fclose(fp);
	return v;
}

double psd_wallstep_wall(void)
{
	return psd_time_wall() + test_offset();
}

/* Wall minus monotonic, read as close together as two calls allow. */
static double wall_minus_mono(void)
{
	double m = psd_time_mono();
	return psd_wallstep_wall() - m;
}

void psd_wallstep_init(struct psd_wallstep *w, double threshold)
{
	w->offset = wall_minus_mono();
	w->threshold = threshold;
}

double psd_wallstep_check(struct psd_wallstep *w)
{
	double now = wall_minus_mono(), step = now - w->offset;
	if (!(fabs(step) > w->threshold))
		return 0;
	w->offset = now;
	return step;
}
