/* SPDX-License-Identifier: ISC */
/* Exact weights of a sensor that changes with azimuth (no symmetry to
 * mirror): wall time of ps_weights_build on every core, cold (nothing
 * cached), and the error of the map's total against the sensitivity's
 * integral over the sphere (the table ends at 90 degrees, inside the
 * 180-degree field, so the two are equal analytically).  One run each on
 * whatever else the machine is doing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "sensor.h"
#include "view.h"
#include "weights.h"
#include "time.h"

int main(void)
{
	static const char table[] = "degrees 0 45 90 135 180 225 270 315\n"
	                            "0 1 1 1 1 1 1 1 1\n"
	                            "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
	                            "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
	                            "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
	                            "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
	                            "90 0 0 0 0 0 0 0 0\n";
	static const int sizes[] = { 1000, 4000 };
	static const double goals[] = { 25, 350 };
	struct ps_sensor s;
	struct ps_view v;
	struct ps_err e;
	ps_view_default_fisheye(&v);
	if (ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0)
		return 1;
	printf("exact weights of a sensor that changes with azimuth (8 x 6 table), 180-degree\n"
	       "angular fisheye, every core, cold; error: map total against the sensitivity's\n"
	       "integral\n");
	printf("%-40s %10s %10s %8s %5s\n", "route", "error", "ms", "goal ms", "met");
	for (int r = 0; r < 2; r++) {
		if (ps_sensor_set_reading(&s, r == 0 ? PS_READ_LINEAR : PS_READ_CELL, &e) != 0)
			return 1;
		for (int k = 0; k < 2; k++) {
			struct ps_weights w;
			char name[64];
			double t0 = psd_time_mono(), ms;
			if (ps_weights_build(&w, &s, 10.0, &v, sizes[k], sizes[k], PS_W_EXACT, &e) != 0)
				return 1;
			ms = 1e3 * (psd_time_mono() - t0);
			snprintf(name, sizeof name, "weights %dx%d, %s reading", sizes[k], sizes[k],
			         r == 0 ? "linear" : "cell");
			printf("%-40s %10.2e %10.1f %8.0f %5s\n", name, w.sens_sum / w.sens_full - 1, ms,
			       goals[k], ms <= goals[k] ? "yes" : "no");
			ps_weights_free(&w);
		}
	}
	ps_sensor_free(&s);
	return 0;
}
