/* SPDX-License-Identifier: ISC */
/* The point model: each zone's points defined once (key, name, unit, kind,
 * writability, description, the states of a multi-state point), and their
 * values read from the engine.  Every front end lists its points from this
 * one table: the control socket's status (each zone's "points" object,
 * keyed by `key`), MQTT (the state's "points" object and one Home
 * Assistant entity per point), BACnet (one object per point: daemon/bacnet/
 * bacobj.c) and Prometheus (psensd_<key>{zone="..."}), so a point added
 * here appears everywhere at once and its names never drift apart.
 *
 * A zone has a point unless the point needs what the zone lacks: a task
 * meter (measured task lux, drift, acceptance), an occupancy input, a
 * power curve (kWh: [simulate] lamp_watts) or a simulation (the ratio and
 * its source).  Values are in the point's unit (a level in %, not the
 * status' fractions); a binary point is 0 or 1; a multi-state point is
 * 1..n, its state names[value - 1]. */
#ifndef PSD_POINTS_H
#define PSD_POINTS_H

#include <json-c/json.h>
#include <stddef.h>

#include "annual.h"
#include "config.h"

struct psd_engine;
struct psd_zone;

enum psd_points_kind { PSD_POINTS_ANALOG, PSD_POINTS_BINARY, PSD_POINTS_MULTISTATE };

struct psd_points_def {
	const char *key;            /* status/MQTT "points" key, Prometheus psensd_<key> */
	const char *name;           /* "<zone> <name>": BACnet Object_Name, Home Assistant name */
	const char *unit;           /* "%", "lx", "V", "h", "kWh"; NULL: none (binary, multi-state) */
	enum psd_points_kind kind;
	int writable;               /* a front end may command it (level: override, target_lux: target) */
	const char *description;
	const char *const *states;  /* multi-state: the state names, NULL-terminated */
	unsigned bacnet_units;      /* analog: BACnetEngineeringUnits */
	const char *ha_class;       /* Home Assistant device_class, NULL: none */
	/* a writable point other than the level (a BACnet Value, commandable):
	 * the range a write must keep to, in the unit */
	double min, max;
};

/* The zone-level state the engine does not keep: the energy integrated
 * since psensd started (over reloads, by zone name) and the verdict of
 * the last acceptance run (read from the log when the zone first appears,
 * then set by each accept-test). */
struct psd_points_zone {
	char name[48];      /* the zone's name (psd_zone_conf) */
	double t;          /* clock time of the last integration; NAN: none yet */
	double output_h;   /* light-output hours (hours at full output) */
	double kwh;        /* with a power curve */
	int verdict;       /* 0 none, else a state of the acceptance point (1-based) */
	const struct psd_config *curve_of; /* the configuration curve was read from */
	struct psd_annual_opt curve;       /* its power curve (kWh) */
	int have_curve;
};
struct psd_points {
	struct psd_points_zone zone[PSD_MAX_ZONES]; /* the slots in use first */
	int slot[PSD_MAX_ZONES];                    /* the engine's zone i's slot + 1 (0: unknown) */
};

/* The table: psd_points_count() entries. */
size_t psd_points_count(void);
const struct psd_points_def *psd_points_def(size_t i);
/* The index of key, -1 when there is none. */
int psd_points_find(const char *key);
/* The number of states of point i (0 unless multi-state). */
size_t psd_points_nstates(size_t i);

/* 1 when zone zi of e has point i, else 0. */
int psd_points_has(const struct psd_engine *e, size_t zi, size_t i);
/* Point i of zone zi at clock time now into *v (NAN: no reading now): 0,
 * or -1 when the zone lacks the point.  p may be NULL (energy and the
 * verdict are then absent). */
int psd_points_value(const struct psd_points *p, const struct psd_engine *e, size_t zi, size_t i, double now,
                     double *v);
/* A writable point's configured value (what holds when no one commands
 * it: BACnet's Relinquish_Default): 0, or -1 when zone zi lacks point i or
 * the point is not a writable one other than the level. */
int psd_points_default(const struct psd_engine *e, size_t zi, size_t i, double *v);
/* Command writable point i of zone zi to v (the target lux, daylight
 * control on 1 or off 0, the vacancy hold in s), logged by the engine: 0,
 * or -1 with a message in err (no such point in the zone, not writable
 * this way, v outside [min, max]).  The level is commanded as an override
 * instead (psd_engine_override). */
int psd_points_write(struct psd_engine *e, size_t zi, size_t i, double v, char *err, size_t n);
/* The zone's occupancy: -1 no occupancy input, 0 vacant, 1 occupied. */
int psd_points_occupancy(const struct psd_zone *z);

/* Integrate the energy up to now (call once a loop turn); a zone that is
 * new by name starts at zero. */
void psd_points_update(struct psd_points *p, const struct psd_engine *e, double now);
/* The last acceptance run's overall verdict (psd_accept_overall's text)
 * for zone name. */
void psd_points_set_verdict(struct psd_points *p, const char *zone, const char *overall);

/* Zone zi's points as a JSON object {key: value}: a number in the unit, a
 * binary as true/false, a multi-state as its state's name. */
json_object *psd_points_json(const struct psd_points *p, const struct psd_engine *e, size_t zi, double now);
/* Every zone's points in the Prometheus text exposition format (# HELP,
 * # TYPE, psensd_<key>{zone="..."}, a gauge each; a point in hours, key
 * X_h, in Prometheus' base unit as psensd_X_seconds; a multi-state point
 * one series per state, 1 for the one in force).  A string to free(), NULL (errno) when
 * memory ran out. */
char *psd_points_prometheus(const struct psd_points *p, const struct psd_engine *e, double now);

#endif
