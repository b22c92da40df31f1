/* SPDX-License-Identifier: ISC */
/* The loopback driver: the virtual room (room.h) behind the driver table.
 * Its keys are in lb_options below (psensd.conf(5) and psensd -L list
 * them); the obstruct fault makes the sensor see half its daylight, drift
 * for the daemon to find.  Points: role sensor (volts), task (lux), dim
 * (light output; read back gives the ballast's output), relay (the room's
 * lights are the fraction of relays closed when no dim point drives them: a
 * stepped system), input (an occupancy sensor with `occupied`, optional
 * random short `absences` inside those times drawn from the device's seed,
 * one draw per day so a day replays the same, and `dead` times when it does
 * not answer; its changes delivered as events through deadline/service). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loopback.h"
#include "replay.h"

enum { LB_MAX_RELAYS = 8, LB_MAX_INPUTS = 4, LB_MAX_WINDOWS = 8, LB_MAX_ABSENCES = 16 };

struct loopback {
	struct ps_room_params opts;   /* from the device options */
	struct ps_room_fault_window faults[16];
	struct ps_room_daypoint *replay;   /* the replayed day, or NULL */
	size_t nreplay;
	struct ps_room *room;
	int ndim, nrelay, relay_on[LB_MAX_RELAYS];
	struct lb_input {
		struct ps_point *pt;
		double win[LB_MAX_WINDOWS][2];   /* occupied from, to (time of day) */
		double dead[LB_MAX_WINDOWS][2];  /* not answering from, to */
		int nwin, ndead, state;          /* state: -1 not reported yet */
		long absences;                   /* short absences a day */
		double absence_s;                /* the longest, s (each from half of it) */
		uint64_t seed;
	} input[LB_MAX_INPUTS];
	int ninput;
	double serviced;                     /* inputs are reported up to here */
};

static const char *const fault_names[] = { "stuck", "open", "saturated", "drop", "late", "ballast", "obstruct",
                                           NULL };   /* enum ps_room_fault, from 1 */

#define DEV PS_OPT_DEVICE
static const struct ps_opts_spec lb_options[] = {
	{ .key = "gain", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "1", .min = 0, .max = 1e9,
	  .doc = "volts per unit of sensor response" },
	{ .key = "offset", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0",
	  .min = -100, .max = 100, .doc = "volts added to the sensor's signal" },
	{ .key = "noise", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0", .min = 0, .max = 100,
	  .doc = "the sensor's noise, volts (standard deviation)" },
	{ .key = "saturation", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "10",
	  .min = 0, .max = 1000, .doc = "volts at which the sensor clips" },
	{ .key = "task_noise", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0",
	  .min = 0, .max = 1e6, .doc = "the task meter's noise, lux (standard deviation)" },
	{ .key = "seed", .type = PS_OPT_LONG, .scope = DEV, .def = "1",
	  .min = 0, .max = 0x7fffffff, .doc = "the noise's seed: a run is reproducible" },
	{ .key = "fade_rate", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0",
	  .min = 0, .max = 1e6,
	  .doc = "the ballast's fade, fraction of full output per second (0: instant)" },
	{ .key = "min_level", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.01",
	  .min = 0, .max = 1, .doc = "the ballast's lowest output above off" },
	{ .key = "lag_tau", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.05",
	  .min = 0, .max = 1e6, .doc = "the lamp's time constant, seconds" },
	{ .key = "off_below_min", .type = PS_OPT_BOOL, .scope = DEV, .def = "yes",
	  .doc = "a command below min_level switches off (no: holds min_level)" },
	{ .key = "faults", .type = PS_OPT_WINDOWS, .scope = DEV, .min = 0, .max = 16,
	  .names = fault_names, .doc = "faults by time of day: KIND HH:MM-HH:MM, ..." },
	{ .key = "replay", .type = PS_OPT_STRING, .scope = DEV,
	  .doc = "a CSV written by psensctl export --csv: its day of daylight replaces the scene's" },
	{ .key = "replay_ratio", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0",
	  .min = 0, .max = 1e9, .doc = "lux per daylight volt, for a replay without daylight_lux" },
	{ .key = "occupied", .type = PS_OPT_WINDOWS, .scope = PS_OPT_POINT,
	  .roles = PS_ROLE_BIT(PS_ROLE_INPUT), .min = 0, .max = LB_MAX_WINDOWS,
	  .doc = "an occupancy input's occupied times: HH:MM-HH:MM, ..." },
	{ .key = "absences", .type = PS_OPT_LONG, .scope = PS_OPT_POINT, .roles = PS_ROLE_BIT(PS_ROLE_INPUT),
	  .def = "0", .min = 0, .max = LB_MAX_ABSENCES,
	  .doc = "short absences a day at random times inside the occupied times (the device's seed)" },
	{ .key = "absence_length", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .roles = PS_ROLE_BIT(PS_ROLE_INPUT),
	  .def = "1200", .min = 1, .max = 86400,
	  .doc = "the longest absence, s: each lasts between half of it and it" },
	{ .key = "dead", .type = PS_OPT_WINDOWS, .scope = PS_OPT_POINT, .roles = PS_ROLE_BIT(PS_ROLE_INPUT),
	  .min = 0, .max = LB_MAX_WINDOWS,
	  .doc = "times the input does not answer (a device gone): HH:MM-HH:MM, ..." },
	{ .key = NULL },
};
#undef DEV

static int lb_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct loopback *lb = calloc(1, sizeof *lb);
	struct ps_opts_reader r = { o, lb_options, PS_OPT_DEVICE, dev->err, sizeof dev->err, NULL };
	struct ps_opts_window w[16];
	const char *replay = NULL;
	size_t nw;
	long seed;
	int off;
	if (!lb)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = lb;
	if (ps_opts_double(&r, "gain", &lb->opts.gain) || ps_opts_double(&r, "offset", &lb->opts.offset) ||
	    ps_opts_double(&r, "noise", &lb->opts.noise) || ps_opts_double(&r, "saturation", &lb->opts.saturation) ||
	    ps_opts_double(&r, "task_noise", &lb->opts.task_noise) || ps_opts_long(&r, "seed", &seed) ||
	    ps_opts_double(&r, "fade_rate", &lb->opts.ballast.fade_rate) ||
	    ps_opts_double(&r, "min_level", &lb->opts.ballast.min_level) ||
	    ps_opts_double(&r, "lag_tau", &lb->opts.ballast.lag_tau) || ps_opts_choice(&r, "off_below_min", &off) ||
	    ps_opts_windows(&r, "faults", w, &nw) || ps_opts_string(&r, "replay", &replay))
		return -1;
	lb->opts.seed = (uint64_t)seed;
	lb->opts.ballast.off_below_min = off;
	for (size_t i = 0; i < nw; i++)
		lb->faults[i] = (struct ps_room_fault_window){ w[i].kind + 1, w[i].start, w[i].end };
	lb->opts.faults = lb->faults;
	lb->opts.nfaults = nw;
	if (replay) {
		double ratio;
		char err[512];
		if (ps_opts_double(&r, "replay_ratio", &ratio) != 0)
			return -1;
		if (ps_replay_read(replay, lb->opts.gain, ratio, &lb->replay, &lb->nreplay, err, sizeof err) != 0)
			return ps_dev_fail(dev, EINVAL, "%s:%d: replay: %s", o->file, ps_opts_line(o, "replay"), err);
	}
	return 0;
}

/* The setup method: give an opened loopback device its room.  The daemon
 * builds the daylight and electric responses from the scene results; the
 * device's own options (noise, gain, ballast, faults) are merged in.  Called
 * once, after open. */
static int ps_loopback_set_room(struct ps_dev *dev, const struct ps_room_params *p, double now)
{
	struct loopback *lb = dev->priv;
	struct ps_room_params merged = *p;
	if (!lb)
		return ps_dev_fail(dev, EINVAL, "loopback: not open");
	merged.gain = lb->opts.gain;
	merged.offset = lb->opts.offset;
	merged.noise = lb->opts.noise;
	merged.saturation = lb->opts.saturation;
	merged.task_noise = lb->opts.task_noise;
	merged.seed = lb->opts.seed;
	merged.ballast = lb->opts.ballast;
	merged.faults = lb->opts.faults;
	merged.nfaults = lb->opts.nfaults;
	if (lb->replay) {
		merged.daylight = lb->replay;
		merged.ndaylight = lb->nreplay;
	}
	ps_room_free(lb->room);
	lb->room = ps_room_new(&merged, now);
	lb->serviced = now;
	return lb->room ? 0 : ps_dev_fail(dev, ENOMEM, "out of memory");
}

static int read_windows(struct ps_dev *dev, struct lb_input *in, const struct ps_opts *o)
{
	struct ps_opts_reader r = { o, lb_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	struct ps_opts_window w[LB_MAX_WINDOWS];
	size_t n;
	if (ps_opts_windows(&r, "occupied", w, &n) != 0)
		return -1;
	for (size_t i = 0; i < n; i++) {
		in->win[i][0] = w[i].start;
		in->win[i][1] = w[i].end;
	}
	in->nwin = (int)n;
	if (ps_opts_windows(&r, "dead", w, &n) != 0 || ps_opts_long(&r, "absences", &in->absences) != 0 ||
	    ps_opts_double(&r, "absence_length", &in->absence_s) != 0)
		return -1;
	for (size_t i = 0; i < n; i++) {
		in->dead[i][0] = w[i].start;
		in->dead[i][1] = w[i].end;
	}
	in->ndead = (int)n;
	return 0;
}

static int lb_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct loopback *lb = dev->priv;
	switch (pt->role) {
	case PS_ROLE_SENSOR:
	case PS_ROLE_TASK_LUX:
	case PS_ROLE_ROOFTOP:
		return 0;
	case PS_ROLE_DIM:
		lb->ndim++;
		return 0;
	case PS_ROLE_RELAY:
		if (lb->nrelay >= LB_MAX_RELAYS)
			return ps_dev_fail(dev, EINVAL, "loopback: at most %d relays", LB_MAX_RELAYS);
		pt->priv = &lb->relay_on[lb->nrelay++];
		return 0;
	case PS_ROLE_INPUT: {
		struct lb_input *in = &lb->input[lb->ninput];
		if (lb->ninput >= LB_MAX_INPUTS)
			return ps_dev_fail(dev, EINVAL, "loopback: at most %d inputs", LB_MAX_INPUTS);
		memset(in, 0, sizeof *in);
		in->pt = pt;
		in->state = -1;
		in->seed = lb->opts.seed ^ (0xd1b54a32d192ed03ULL * (uint64_t)(lb->ninput + 1));
		if (read_windows(dev, in, o) != 0)
			return -1;
		pt->priv = in;
		lb->ninput++;
		return 0;
	}
	default:
		return ps_dev_fail(dev, EINVAL, "loopback: no %s points", ps_role_name(pt->role));
	}
}

static uint64_t splitmix64(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

static int in_windows(const double (*win)[2], int n, double tod)
{
	for (int i = 0; i < n; i++) {
		double a = win[i][0], b = win[i][1];
		if (a <= b ? (tod >= a && tod < b) : (tod >= a || tod < b))   /* across midnight */
			return 1;
	}
	return 0;
}

/* The absences of the day starting at day0 (clock seconds of its midnight),
 * as times of day from, to: each starts uniformly in the day's occupied time
 * (its windows laid end to end) and lasts uniformly half the longest to
 * the longest, cut at midnight.  The draw depends only on the seed and the
 * day, so every call gives the same. */
static int absences_of_day(const struct lb_input *in, double day0, double out[][2])
{
	double total = 0;
	uint64_t st = in->seed ^ (0x9e3779b97f4a7c15ULL * (uint64_t)(int64_t)floor(day0 / 86400.0 + 0.5));
	int n = 0;
	for (int i = 0; i < in->nwin; i++)
		total += in->win[i][0] <= in->win[i][1] ? in->win[i][1] - in->win[i][0]
		                                        : 86400 - in->win[i][0] + in->win[i][1];
	if (!(total > 0))
		return 0;
	for (long k = 0; k < in->absences; k++) {
		double pos = (splitmix64(&st) >> 11) * 0x1p-53 * total;
		double len = in->absence_s * (0.5 + 0.5 * (splitmix64(&st) >> 11) * 0x1p-53), from = 0;
		for (int i = 0; i < in->nwin; i++) {
			double a = in->win[i][0], b = in->win[i][1], w = a <= b ? b - a : 86400 - a + b;
			if (pos < w || i == in->nwin - 1) {
				from = fmod(a + pos, 86400.0);
				break;
			}
			pos -= w;
		}
		out[n][0] = from;
		out[n][1] = from + len < 86400 ? from + len : 86400;
		n++;
	}
	return n;
}

static int dead(const struct lb_input *in, double now)
{
	return in_windows(in->dead, in->ndead, ps_room_tod(now));
}

static int occupied(const struct lb_input *in, double now)
{
	double tod = ps_room_tod(now), ab[LB_MAX_ABSENCES][2];
	int n;
	if (!in_windows(in->win, in->nwin, tod))
		return 0;
	n = absences_of_day(in, now - tod, ab);
	for (int i = 0; i < n; i++)
		if (tod >= ab[i][0] && tod < ab[i][1])
			return 0;
	return 1;
}

static void earliest_after(double t, double after, double *next)
{
	if (t > after && t < *next)
		*next = t;
}

/* The next change of any input after the last service (INFINITY: none). */
static double lb_deadline(struct ps_dev *dev, double *mono)
{
	(void)mono;
	struct loopback *lb = dev->priv;
	double next = INFINITY, day0;
	if (!lb || !lb->room || lb->ninput == 0)
		return INFINITY;
	for (int i = 0; i < lb->ninput; i++)
		if (lb->input[i].state < 0 && !dead(&lb->input[i], lb->serviced))
			return lb->serviced;   /* the first state is reported at once */
	day0 = lb->serviced - ps_room_tod(lb->serviced);
	for (int i = 0; i < lb->ninput; i++) {
		const struct lb_input *in = &lb->input[i];
		for (int d = 0; d < 2; d++) {
			double dd = day0 + d * 86400.0, ab[LB_MAX_ABSENCES][2];
			int n = absences_of_day(in, dd, ab);
			for (int e = 0; e < 2; e++) {
				for (int w = 0; w < in->nwin; w++)
					earliest_after(dd + in->win[w][e], lb->serviced, &next);
				for (int w = 0; w < in->ndead; w++)
					earliest_after(dd + in->dead[w][e], lb->serviced, &next);
				for (int w = 0; w < n; w++)
					earliest_after(dd + ab[w][e], lb->serviced, &next);
			}
		}
	}
	return next;
}

static int lb_service(struct ps_dev *dev, double now, double mono)
{
	(void)mono;
	struct loopback *lb = dev->priv;
	if (!lb || !lb->room)
		return 0;
	for (int i = 0; i < lb->ninput; i++) {
		struct lb_input *in = &lb->input[i];
		int st = occupied(in, now);
		if (dead(in, now)) {
			in->state = -1;   /* silent; reported afresh when it answers */
			continue;
		}
		if (st != in->state) {
			in->state = st;
			if (dev->on_event)
				dev->on_event(dev->event_user, dev, in->pt, now, st);
		}
	}
	if (now > lb->serviced)
		lb->serviced = now;
	return 0;
}

/* The sensor clips at its saturation: the simulated input's full scale. */
static int lb_full_scale(struct ps_dev *dev, struct ps_point *pt, double *limit)
{
	struct loopback *lb = dev->priv;
	if (!lb || pt->role != PS_ROLE_SENSOR || !(lb->opts.saturation > 0))
		return -1;
	*limit = lb->opts.saturation;
	return 0;
}

static int lb_read(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *value)
{
	(void)mono;
	struct loopback *lb = dev->priv;
	if (!lb->room)
		return ps_dev_fail(dev, ENODEV, "loopback %s: no room", dev->name);
	if (pt->role == PS_ROLE_SENSOR) {
		if (ps_room_sensor(lb->room, now, value) != 0)
			return ps_dev_fail(dev, errno, "loopback %s: sensor reply %s", dev->name,
			                   ps_room_fault(lb->room, now) == PS_ROOM_FAULT_LATE ? "late" : "dropped");
		return 0;
	}
	if (pt->role == PS_ROLE_TASK_LUX)
		return ps_room_task(lb->room, now, value);
	if (pt->role == PS_ROLE_ROOFTOP) {
		if (ps_room_rooftop(lb->room, now, value) != 0)
			return ps_dev_fail(dev, ENODATA, "loopback %s: the room's day has no rooftop reading "
			                   "(a day of the year has one: [simulate] year = yes)", dev->name);
		return 0;
	}
	if (pt->role == PS_ROLE_RELAY) {
		*value = *(int *)pt->priv;
		return 0;
	}
	if (pt->role == PS_ROLE_INPUT) {
		if (dead(pt->priv, now))
			return ps_dev_fail(dev, ENODEV, "loopback %s: input %s does not answer", dev->name, pt->name);
		*value = occupied(pt->priv, now);
		return 0;
	}
	*value = ps_room_output(lb->room, now);
	return 0;
}

static int lb_write(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double value)
{
	(void)mono;
	struct loopback *lb = dev->priv;
	if (!lb->room)
		return ps_dev_fail(dev, ENODEV, "loopback %s: no room", dev->name);
	if (pt->role == PS_ROLE_RELAY) {
		int on = 0;
		*(int *)pt->priv = value > 0.5;
		if (lb->ndim)
			return 0;   /* the dim point drives the room */
		for (int i = 0; i < lb->nrelay; i++)
			on += lb->relay_on[i];
		ps_room_command(lb->room, now, (double)on / lb->nrelay);
		return 0;
	}
	if (pt->role != PS_ROLE_DIM)
		return ps_dev_fail(dev, EINVAL, "loopback: %s is not an output", pt->name);
	ps_room_command(lb->room, now, value);
	return 0;
}

static int lb_truth(struct ps_dev *dev, double now, struct ps_truth *t)
{
	struct loopback *lb = dev->priv;
	int fault;
	if (!lb || !lb->room)
		return ps_dev_fail(dev, ENODEV, "loopback %s: no room", dev->name);
	ps_room_truth(lb->room, now, t);
	fault = ps_room_fault(lb->room, now);
	t->fault = fault > 0 && fault < PS_ROOM_FAULT_COUNT ? fault_names[fault - 1] : NULL;   /* names from stuck (1) */
	return 0;
}

static void lb_close(struct ps_dev *dev)
{
	struct loopback *lb = dev->priv;
	if (lb) {
		ps_room_free(lb->room);
		free(lb->replay);
	}
	free(lb);
	dev->priv = NULL;
}

const struct ps_driver ps_driver_loopback = {
	.name = "loopback",
	.summary = "the virtual room built from the scene's simulated ratios",
	.compiled_in = 1,
	.options = lb_options,
	.open = lb_open,
	.add_point = lb_add_point,
	.read = lb_read,
	.write = lb_write,
	.deadline = lb_deadline,
	.service = lb_service,
	.close = lb_close,
	.setup = ps_loopback_set_room,
	.truth = lb_truth,
	.full_scale = lb_full_scale,
};
