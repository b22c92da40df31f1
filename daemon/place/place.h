/* SPDX-License-Identifier: ISC */
/* psplace's room: the search's shared types.  A candidate pose with its
 * projected rows, the year's hours shared by every combination, one
 * combination's scores, the options and the search that holds them
 * (placeset.h reads and projects the poses, placeyear.h makes the year,
 * placerun.h runs and ranks the combinations, placeout.h writes them). */
#ifndef PSD_PLACE_H
#define PSD_PLACE_H

#include <pthread.h>
#include <stddef.h>

#include "annual.h"
#include "config.h"
#include "control.h"
#include "sensor.h"
#include "view.h"
#include "weather.h"
#include "year.h"

#define PSD_PLACE_MAX_LIST 64

struct pose {
	char id[64];
	char view_text[512];
	struct ps_view view;
	double *row;       /* nrot x nsens x npatch x 3 (projection route), per channel */
	double *elec;      /* nrot x nsens: the response to the electric picture */
	char dcdir[4096];  /* rendered: the cache's folder of its coefficient pictures */
	char elecfile[4096];   /* rendered: the cache's electric picture */
};

/* the year's hours with light, shared by every combination */
struct hours {
	size_t n;
	struct ps_year_hour *h;   /* sensor left 0: filled per combination */
	double *sky;              /* n x npatch x 3 */
	double *task;             /* n: the grid's figure of daylight lux */
	int npatch, leap;
	struct ps_site site;
	/* the grid point by point, for a figure that is not linear in its
	 * points (min, pNN) */
	int npoints;
	double *pt_day;           /* n x npoints: each point's daylight lux (NULL: the figure is linear) */
	double *pt_elec;          /* npoints: each point's electric lux at full output */
	size_t day_first[368];    /* the hours of day of year d (from 1): day_first[d] to day_first[d + 1] */
	/* the ideal photocell's output (psd_placeyear_ideal) at every occupied
	 * step of the year, the same for every combination: 366 x ideal_steps
	 * (day d's step i at [(d - 1) ideal_steps + i], NAN where not made), or
	 * NULL */
	double *ideal;
	long ideal_steps;
	double ideal_period, ideal_target;
};

struct combo {
	int pose, rot, sens, law;
	int exact;                 /* run again with the exact route */
	struct psd_annual a;
	double deficit_lxh;        /* sum over occupied time of (target - task), where below */
	double over_h;             /* hours with more light output than the ideal photocell's + 0.01 */
	double spread[PS_SKY_NCLASS];   /* task/sensor ratio: sd / mean by sky class, % */
	double spread_max;
	double days_pass, days;    /* days passing the acceptance tests, days judged */
	double sensor_sum;         /* the year's sensor signal (for the exact check) */
	double exact_sensor_err, exact_energy_err;   /* projection against exact, % */
	int pareto;
	int fail;
};

struct opts {
	const char *conf, *zone, *cands, *dir, *grid, *elec, *weather, *stat;
	const char *json_out, *results_out, *schedule, *csv, *zone_out, *plan, *fisheye;
	/* rendering (placerender.h): rfluxmtx's octree and sky patches, rpict's
	 * octree, their options and sizes, the cache, renderers at once */
	const char *dc_octree, *receiver, *elec_octree, *dc_options, *elec_options, *cache;
	const char *ceiling, *aims;   /* poses made on a ceiling grid, with their aims */
	int dc_size, elec_size, jobs;
	const char *sens[PSD_PLACE_MAX_LIST];       /* as given: a sensor, @ and its filter */
	char sens_path[PSD_PLACE_MAX_LIST][1024];   /* the sensor's table or builtin */
	double coef[PSD_PLACE_MAX_LIST][3];          /* its colour weights (R, G, B) */
	int nsens;
	int laws[PSD_ALG_COUNT], nlaws;
	int nrot, top, threads, quiet, json;
	double rot_step;
	double period, cell_theta, max_below;
};

struct search {
	const struct opts *o;
	struct psd_config *cf;
	const struct psd_zone_conf *zc;
	struct pose *poses;
	int nposes;
	struct ps_sensor *sens;
	int npatch, mf;
	double cell_theta;         /* degrees: the projection's cells in polar angle */
	double theta_max;          /* degrees: the projection's extent (the sensors') */
	struct hours hrs;
	double elec_task;          /* the grid's figure at full electric output */
	struct psd_annual_opt ao;
	struct combo *c;
	size_t nc;
	size_t next;
	pthread_mutex_t lock;
	int failed;
};

#endif
