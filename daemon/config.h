/* SPDX-License-Identifier: ISC */
/* psensd.conf: the daemon's whole configuration, read and checked in one
 * pass (every error as file:line), so that `psensd -n` and SIGHUP can judge
 * a file before anything is changed.  See psensd.conf(5).
 *
 *   [psensd]          results, scene, database, socket, period, safe_level, ...
 *   [simulate]        the day the loopback room plays (date, sunrise, ...)
 *   [device NAME]     driver = NAME and the driver's own keys
 *   [point NAME]      device = NAME, role = sensor|task|dim|relay|input, the
 *                     daemon's keys (min, max, action) and the driver's keys
 *   [zone NAME]       sensor, task, dim, relay, input points and the control
 *
 * A zone may name `device = NAME` instead of points: it then gets a sensor
 * and a dim point on that device with no options (the loopback shorthand). */
#ifndef PSD_CONFIG_H
#define PSD_CONFIG_H

#include <stddef.h>

#include "conf.h"
#include "control.h"
#include "driver.h"
#include "bacnet.h"
#include "mqtt.h"
#include "prom.h"
#include "web.h"

enum {
	PSD_MAX_DEVICES = 16,
	PSD_MAX_POINTS = 512,
	PSD_MAX_ZONES = 128,
	PSD_MAX_ZONE_OUT = 8,     /* dim, relay or input points of one zone */
	PSD_MAX_OPTS = 4096,      /* driver options, all devices and points together */
};

enum psd_action { PSD_ACT_NONE = 0, PSD_ACT_OCCUPANCY, PSD_ACT_OVERRIDE, PSD_ACT_CALIBRATE };

struct psd_device_conf {
	char name[48];
	const struct ps_driver *drv;
	struct ps_opts opts;      /* the section's keys but `driver` and `simulated` */
	char simulated[64];       /* `simulated = WHAT`: a device that is a simulation
	                             (psvirt's virtual rooms), "" for a real one */
	int line;
};

struct psd_point_conf {
	char name[48];
	int device;               /* index into devices */
	int role;                 /* enum ps_role */
	int action;               /* inputs: enum psd_action */
	double min, max;          /* valid range of a reading (sensor volts, task lux) */
	double saturation;        /* sensor: volts at which it saturates (0: unknown) */
	struct ps_opts opts;      /* the driver's keys */
	int line;
};

/* stop_level: what a planned stop (SIGTERM, SIGINT, a simulated run's
 * end) leaves a zone at; a fault always leaves the safe level. */
enum psd_stop_mode {
	PSD_STOP_SAFE,            /* the safe level; a vacant zone keeps its level */
	PSD_STOP_HOLD,            /* nothing commanded: the gear keep the last level */
	PSD_STOP_LEVEL,           /* every zone to level, vacant or not */
};
struct psd_stop {
	int mode;                 /* enum psd_stop_mode */
	double level;             /* PSD_STOP_LEVEL: 0-1 */
};

struct psd_zone_conf {
	char name[48];
	int sensor;               /* point index */
	int task;                 /* point index or -1 */
	int rooftop;              /* point index or -1: the live estimate's sky class */
	int dim[PSD_MAX_ZONE_OUT], ndim;
	int relay[PSD_MAX_ZONE_OUT], nrelay;
	int input[PSD_MAX_ZONE_OUT], ninput;
	struct psd_control ctl;   /* constants; state is zeroed */
	double period;            /* seconds between control steps */
	double safe_level;        /* light output on a fault */
	struct psd_stop stop;     /* what a planned stop leaves (psensd(8), STOPPING) */
	double stale_after;       /* no good reading for this long: fault (s) */
	double stuck_after;       /* an unchanged reading for this long: fault (s), 0: off */
	double verify_tolerance;  /* read dim points back: a ballast that differs by more
	                             than this one period after a command is a fault; 0: off */
	int readback;             /* read the first dim point's actual output before each step */
	double override_s;        /* a button's override lasts this long */
	double vacancy_s;         /* occupancy: vacant this long, the vacant level (vacancy_hold) */
	double vacant_level;      /* occupancy: the light output then (0: off) */
	/* calibration sessions and drift (psensd.conf(5)) */
	double cal_window;        /* settling window, s */
	double cal_timeout;       /* longest wait at one night level, s */
	double cal_floor;         /* volts: a change always allowed as settled */
	long cal_day_samples;     /* day samples from a meter */
	double cal_day_interval;  /* s between them */
	double cal_min_day_volts; /* less daylight signal: not a day sample */
	double cal_tolerance;     /* % error against the design still a pass */
	double cal_dark_margin;   /* night: daylight above the electric-only expectation, as a
	                             fraction of the full-output electric signal, that refuses
	                             or aborts a night session */
	int cal_night_sun;        /* night: refuse while the simulation's sun is up */
	double cal_sun_share;     /* day: a brightest patch above this share of the simulated
	                             response is the sun in the sensor's view (a warning) */
	double drift_margin;      /* |ln(measured/simulated)| */
	double drift_hold;        /* s */
	/* the zone's own simulation (NULL: [psensd]'s); see psd_config_zone_results() */
	char *scene, *results;
	int line;
};

struct psd_config {
	struct ps_conf conf;      /* owns every string the options point into */
	char *results, *scene, *database, *socket_path;
	const char *timezone;     /* the site's time zone (TZ: a zoneinfo name or a POSIX rule), NULL: the process's */
	double socket_mode;       /* permission bits of the socket (octal in the file) */
	struct psd_stop stop;     /* [psensd] stop_level: the zones' default */
	double period, safe_level, sensor_min, sensor_max, stale_after, stuck_after;
	double sensor_saturation;   /* volts at which a sensor saturates (0: unknown) */
	long max_clients;
	long log_hold;             /* samples held in memory while the log cannot be written */
	/* [simulate] */
	char date[16];
	long run_year;            /* the year a run on a set clock is dated (0: the current year) */
	double start, end, sunrise, sunset, tolerance;
	int sim_year;             /* [simulate] year = yes: the room plays the results' year */
	double occ_from, occ_to;  /* [simulate] occupied_from, occupied_to: psensd -Y's hours */
	double power_at_min;      /* [simulate] input power at the lowest output, fraction
	                             of full (-1: power proportional to light) */
	double lamp_watts;        /* [simulate] input power at full output, W (0: no kWh) */
	int dated_estimate;       /* [psensd] estimate = dated (or sim_year): the dated ratio */
	struct psd_device_conf dev[PSD_MAX_DEVICES];
	size_t ndev;
	struct psd_point_conf pt[PSD_MAX_POINTS];
	size_t npt;
	struct psd_zone_conf zone[PSD_MAX_ZONES];
	size_t nzone;
	struct ps_opt optpool[PSD_MAX_OPTS];
	size_t nopt;
	char *path[PSD_MAX_DEVICES];   /* driver file options resolved against the file's directory */
	size_t npath;
	struct psd_mqtt_conf mqtt;   /* [mqtt] (daemon/mqtt/mqttconf.h, through mqtt.h) */
	struct psd_bacnet_conf bacnet;   /* [bacnet] (daemon/bacnet/bacconf.h, through bacnet.h) */
	struct psd_web_conf web;   /* [web] (daemon/web/webconf.h, through web.h) */
	struct psd_prom_conf prom;   /* [prometheus] (daemon/prom/promconf.h, through prom.h) */
};

/* Read and check path into cf (allocated by the caller, may be large).
 * Returns 0, or -1 with every error in cf->conf.errors (and a read failure
 * as its only error).  psd_config_free() is needed either way. */
int psd_config_load(struct psd_config *cf, const char *path);
/* The same without opening the files it names (scene, results, replays):
 * for readers of the configuration that do not run it (psensctl report). */
int psd_config_load_keys(struct psd_config *cf, const char *path);

/* psd_config_load, and the directories of the files psensd would write
 * (psd_confcheck_outputs): for -n and a reload. */
int psd_config_load_judged(struct psd_config *cf, const char *path);
/* The same from text (tests and fuzzing); path only names it in messages,
 * and the files the text names are not opened (daemon/confcheck.h). */
int psd_config_load_string(struct psd_config *cf, const char *text, const char *path);
void psd_config_free(struct psd_config *cf);

/* The scene and results a zone runs on: its own, else [psensd]'s.  A zone
 * that names a scene but no results gets them beside [psensd]'s results,
 * named after the scene (ofb-cone.scene: ofb-cone.results). */
const char *psd_config_zone_scene(const struct psd_config *cf, const struct psd_zone_conf *zc);
const char *psd_config_zone_results(const struct psd_config *cf, const struct psd_zone_conf *zc);

/* What simulates a zone's sensor, or NULL for a real one: "loopback" or
 * "replay" (drivers that are simulations), or the device's `simulated =`
 * (a Modbus device that is psvirt). */
const char *psd_config_zone_simulated(const struct psd_config *cf, const struct psd_zone_conf *zc);

/* Index of a device or zone by name, -1 if none. */
int psd_config_zone(const struct psd_config *cf, const char *name);

#endif
