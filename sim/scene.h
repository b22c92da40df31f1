/* SPDX-License-Identifier: ISC */
/* A scene: the sensor, the task point and the conditions whose renders give
 * the simulated task-sensor ratios (the scene file, psscene(5)). */
#ifndef PS_SCENE_H
#define PS_SCENE_H

#include <stddef.h>

#include "err.h"
#include "view.h"

enum ps_cond_kind { PS_COND_DAYLIGHT = 0, PS_COND_ELECTRIC = 1 };

struct ps_marks_place {
	double pos[3], dir[3], up[3];   /* where a picture is rendered from */
	int have;                       /* position given */
};

struct ps_condition {
	char *label;
	int kind;                /* enum ps_cond_kind */
	char *date;              /* "MM-DD" or "" */
	double tod_s;            /* time of day, s since midnight; -1 if none */
	char *sensor_pic, *task_pic;   /* resolved paths */
	char *octree;            /* for rendering missing pictures, or NULL */
	int optional;
	double ref_sensor, ref_task;   /* converged reference: sensor response and task
	                                  irradiance (W/m2), NAN when not given */
	int line;                /* of the section, for messages */
};

/* Another render of a condition with other settings (bounces, resolution):
 * psscene prints error against run time for them. */
struct ps_variant {
	char *label, *of;
	char *sensor_pic, *task_pic;
	double render_seconds;   /* NAN when not given */
	int line;
};

struct ps_reference {
	char *label;             /* e.g. "paper measured" */
	double daylight_ratio, electric_ratio, task_sensor_ratio;
	double electric_task_lux, electric_sensor_lux;   /* NAN when absent */
};

/* [daylight_coefficients]: the coefficient picture sets of the two views and
 * the weather whose year psscene runs through them. */
struct ps_dcspec {
	int have;
	int mf;                  /* 0: from the pictures' count */
	char *sensor_pattern, *task_pattern;   /* resolved printf patterns */
	struct ps_view sensor_view, task_view;
	char *task_matrix;       /* a work-plane grid (gridmtx.h) instead of the task's
	                            pictures: resolved, or NULL */
	char *task_points;       /* its rows the task averages ("1,4": from 1), NULL: all */
	char *weather;           /* resolved .wea or .epw, or NULL */
	int weather_illum;       /* take an .epw's illuminances */
	double ground[3];        /* ground reflectance for the year's skies */
	int line;
};

struct ps_scene {
	char *path, *name;
	char *sensitivity;       /* resolved path or builtin:... */
	double rotation;
	int reading;
	double rgb[3];
	char *filter;            /* resolved, or NULL */
	struct ps_marks_place sensor_at, task_at;
	int resolution;          /* for rendering */
	char *render_options;    /* extra rpict options, or NULL */
	char *cache_dir;         /* resolved, or NULL */
	struct ps_condition *cond;
	size_t ncond;
	struct ps_reference *ref;
	size_t nref;
	struct ps_variant *var;
	size_t nvar;
	struct ps_dcspec dc;
};

/* Read a scene file.  Every error (file:line) is reported, all in one pass:
 * the messages are joined with newlines in e->msg. */
int ps_scene_read(struct ps_scene *s, const char *path, struct ps_err *e);
/* The same from a NUL-terminated string; name stands for the file in
 * messages, and relative paths in it are relative to name's directory. */
int ps_scene_parse(struct ps_scene *s, const char *text, const char *name, struct ps_err *e);
void ps_scene_free(struct ps_scene *s);

#endif
