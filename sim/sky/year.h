/* SPDX-License-Identifier: ISC */
/* A year of a weather file through daylight-coefficient rows: for every
 * hour with light (dark hours are skipped: direct + diffuse <= 1e-4, as the
 * sky model makes them), the sky vector of that hour (sky.h, gendaymtx's
 * way) times the sensor's row and the task's row, giving the hour's sensor
 * response and task illuminance; and the table of the expected daylight
 * ratio by month x hour x sky class that psensd's dated estimate reads.
 *
 * Patches whose coefficients are zero in both rows are left out of the sums
 * (they cannot change either signal).  The rows must have one subdivision.
 *
 * Sky class by Perez clearness epsilon: overcast below 1.23 (bins 1-2),
 * clear from 4.5 (bins 7-8), intermediate between.  The table's ratio is the
 * ratio of sums over the cell's hours, sum task lux / sum sensor response
 * (the estimate that is exact for the cell's total light); NAN for an empty
 * cell. */
#ifndef PS_YEAR_H
#define PS_YEAR_H

#include <stddef.h>

#include "dcset.h"
#include "err.h"
#include "sky.h"
#include "weather.h"

enum ps_skyclass { PS_SKY_CLEAR = 0, PS_SKY_INTERMEDIATE = 1, PS_SKY_OVERCAST = 2, PS_SKY_NCLASS = 3 };
#define PS_YEAR_LUX_PER_WM2 179.0

struct ps_year_hour {
	int month, day;
	double hour;          /* standard time, decimal hours, as the weather file */
	double sensor;        /* sensor response */
	double task_lux;      /* 179 x task irradiance (W/m2) */
	int sky_class;        /* enum ps_skyclass */
	double epsilon;       /* Perez clearness of the hour */
	double horiz_lux;     /* global horizontal illuminance (Perez 1990 efficacy):
	                         what a rooftop sensor reads; NAN when a results
	                         file older than the column gives none */
	double sensor_alt;    /* the same hour with the sun's light in its nearest
	                         patch instead of shared among the four nearest
	                         (an equally defensible placement on the same
	                         coefficients: their difference estimates the sun's
	                         discretisation error); NAN when not computed */
	double task_alt;
};

struct ps_year {
	struct ps_year_hour *h;
	size_t n;             /* hours with light */
	size_t steps;         /* steps in the weather file */
	size_t dark;          /* steps skipped as dark */
	int patches, used;    /* patches in the rows, and those with a non-zero coefficient */
	int have_alt;         /* every hour has sensor_alt and task_alt */
	double ratio[12][24][PS_SKY_NCLASS];   /* task lux per unit response; NAN when empty */
	int count[12][24][PS_SKY_NCLASS];
	double mean_ratio;    /* sum task lux / sum response over the year */
	int leap;             /* the weather file has February 29 (its hours may all be dark) */
	int have_site;        /* the weather's site (for the sun of a rooftop reading) */
	struct ps_site site;
};

/* Sky class of a clearness. */
int ps_year_class(double epsilon);
const char *ps_year_class_name(int c);

/* Run the year: srow with the sensor's colour coefficients scoef, trow with
 * V(lambda) (the task).  o: the sky options (ground reflectance, ...); the
 * rows' MF sets the patches.  When o shares the sun among more than one
 * patch (gendaymtx's way, no 5-phase disc), every hour also gets its
 * sensor_alt and task_alt with the sun in its nearest patch (have_alt). */
int ps_year_run(const struct ps_dcset_row *srow, const double scoef[3], const struct ps_dcset_row *trow,
                const struct ps_weather *w, const struct ps_sky_opt *o, struct ps_year *y,
                struct ps_err *e);
/* The table and mean from the hours (ps_year_run calls it; readers too). */
void ps_year_tabulate(struct ps_year *y);
void ps_year_free(struct ps_year *y);

#endif
