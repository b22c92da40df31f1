/* SPDX-License-Identifier: ISC */
/* The results of a scene precompute: per condition the sensor response, the
 * task illuminance and their ratio, and the summaries psensd runs on.  Written
 * by psscene, read by psensd; a versioned INI file (psscene(5)). */
#ifndef PS_RESULTS_H
#define PS_RESULTS_H

#include <stddef.h>

#include "err.h"
#include "year.h"

/* 2: adds the year ([year], [year_hours], [ratio_table]); version 1 files
 * are still read (no year). */
#define PS_RESULTS_VERSION 2

struct ps_result_cond {
	char *label;
	int kind;                 /* enum ps_cond_kind */
	char *date;               /* "MM-DD" or "" */
	double tod_s;             /* seconds since midnight, -1 if none */
	int computed;             /* 0: an optional condition whose pictures were missing */
	double sensor_response;   /* psens Response of the sensor picture */
	double task_irradiance;   /* W/m2 at the task (cosine-weighted) */
	double task_lux;          /* 179 x task_irradiance */
	double ratio;             /* task lux per unit of sensor response */
	double brightest_share;   /* of the sensor response */
};

struct ps_results {
	int version;
	char *scene;              /* scene file */
	char *scene_hash;         /* sha256 of the scene file and every input (hex) */
	char *sensitivity;
	double rotation;
	char *reading;
	double rgb[3];
	struct ps_result_cond *cond;
	size_t ncond;
	/* summaries (NAN when the scene has no condition of that kind) */
	double daylight_ratio_mean, daylight_ratio_min, daylight_ratio_max, daylight_ratio_sd;
	double electric_ratio;          /* task lux per unit response, lights at full output */
	double electric_sensor_response, electric_task_lux;
	double task_sensor_ratio;       /* electric_ratio / daylight_ratio_mean (the paper's Table 1) */
	/* the year through the daylight coefficients (version 2; have = 0 when
	 * the scene has none) */
	int have_year;
	char *weather;                  /* the weather file */
	int year_mf;
	struct ps_year year;            /* hours; the table recomputed by the reader */
};

/* Fill the summaries from the computed conditions. */
void ps_results_summarise(struct ps_results *r);
int ps_results_write(const struct ps_results *r, const char *path, struct ps_err *e);
/* Read a results file; errors name file:line; a newer version is refused. */
int ps_results_read(struct ps_results *r, const char *path, struct ps_err *e);
/* The same from a NUL-terminated string (name stands for the file in messages). */
int ps_results_parse(struct ps_results *r, const char *text, const char *name, struct ps_err *e);
void ps_results_free(struct ps_results *r);

#endif
