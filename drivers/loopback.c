/* The loopback driver.  Device options (psensd.conf [device NAME] with
 * driver = loopback):
 *   gain        volts per unit of sensor response (default 1)
 *   offset      volts (0)           noise        volts, standard deviation (0)
 *   saturation  volts (10)          task_noise   lux, standard deviation (0)
 *   seed        noise seed (1)
 *   fade_rate   fraction per second (0: instant)   min_level  (0.01)
 *   lag_tau     lamp time constant, s (0.05)       off_below_min  yes|no (yes)
 *   faults      "KIND HH:MM-HH:MM, ..." with KIND one of stuck, open,
 *               saturated, drop, late, ballast, obstruct (the sensor sees half
 *               its daylight: drift for the daemon to find)
 *   replay      a CSV written by psensctl export --csv: its day of daylight
 *               replaces the scene's (replay.h)
 *   replay_ratio  lux per daylight volt, for a replay without daylight_lux
 * Points: role sensor (volts), task (lux), dim (light output; read back
 * gives the ballast's output), relay (the room's lights are the fraction of
 * relays closed when no dim point drives them: a stepped system), input
 * (an occupancy sensor: point option `occupied = HH:MM-HH:MM, ...`, its
 * changes delivered as events through deadline/service). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "loopback.h"
#include "replay.h"

enum { LB_MAX_RELAYS = 8, LB_MAX_INPUTS = 4, LB_MAX_WINDOWS = 8 };

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
		int nwin, state;                 /* state: -1 not reported yet */
	} input[LB_MAX_INPUTS];
	int ninput;
	double serviced;                     /* inputs are reported up to here */
};

static const char *const fault_names[] = { "none", "stuck", "open", "saturated", "drop",
                                           "late", "ballast", "obstruct", NULL };

static int parse_faults(struct ps_dev *dev, struct loopback *lb, const struct ps_opts *o)
{
	const char *v = ps_opt_get(o, "faults");
	char *copy, *save = NULL;
	if (!v)
		return 0;
	copy = strdup(v);
	if (!copy)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	for (char *item = strtok_r(copy, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
		char kind[32];
		int h1, m1, h2, m2, k, n = 0;
		if (sscanf(item, " %31s %d:%d-%d:%d %n", kind, &h1, &m1, &h2, &m2, &n) != 5 || item[n]) {
			free(copy);
			return ps_dev_fail(dev, EINVAL, "%s:%d: faults: '%s' is not KIND HH:MM-HH:MM",
			                   o->file, ps_opt_line(o, "faults"), item);
		}
		for (k = 1; fault_names[k] && strcmp(fault_names[k], kind) != 0; k++)
			;
		if (!fault_names[k] || lb->opts.nfaults >= 16) {
			free(copy);
			return ps_dev_fail(dev, EINVAL, "%s:%d: faults: '%s' is not a fault (stuck, open, "
			                   "saturated, drop, late, ballast, obstruct) or too many", o->file,
			                   ps_opt_line(o, "faults"), kind);
		}
		lb->faults[lb->opts.nfaults++] =
		        (struct ps_room_fault_window){ k, h1 * 3600.0 + m1 * 60, h2 * 3600.0 + m2 * 60 };
	}
	free(copy);
	lb->opts.faults = lb->faults;
	return 0;
}

static int lb_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct loopback *lb = calloc(1, sizeof *lb);
	long seed;
	int off = 1;
	static const char *const yesno[] = { "no", "yes", NULL };
	if (!lb)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = lb;
	if (ps_opt_double(o, "gain", 1, 0, 1e9, &lb->opts.gain, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "offset", 0, -100, 100, &lb->opts.offset, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "noise", 0, 0, 100, &lb->opts.noise, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "saturation", 10, 0, 1000, &lb->opts.saturation, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "task_noise", 0, 0, 1e6, &lb->opts.task_noise, dev->err, sizeof dev->err) ||
	    ps_opt_long(o, "seed", 1, 0, 0x7fffffff, &seed, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "fade_rate", 0, 0, 1e6, &lb->opts.ballast.fade_rate, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "min_level", 0.01, 0, 1, &lb->opts.ballast.min_level, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "lag_tau", 0.05, 0, 1e6, &lb->opts.ballast.lag_tau, dev->err, sizeof dev->err) ||
	    ps_opt_enum(o, "off_below_min", yesno, 1, &off, dev->err, sizeof dev->err))
		return -1;
	lb->opts.seed = (uint64_t)seed;
	lb->opts.ballast.off_below_min = off;
	if (parse_faults(dev, lb, o) != 0)
		return -1;
	if (ps_opt_get(o, "replay")) {
		double ratio;
		char err[512];
		if (ps_opt_double(o, "replay_ratio", 0, 0, 1e9, &ratio, dev->err, sizeof dev->err) != 0)
			return -1;
		if (ps_replay_read(ps_opt_get(o, "replay"), lb->opts.gain, ratio, &lb->replay,
		                   &lb->nreplay, err, sizeof err) != 0)
			return ps_dev_fail(dev, EINVAL, "%s:%d: replay: %s", o->file, ps_opt_line(o, "replay"), err);
	}
	return 0;
}

int ps_loopback_set_room(struct ps_dev *dev, const struct ps_room_params *p, double now)
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

struct ps_room *ps_loopback_room(struct ps_dev *dev)
{
	struct loopback *lb = dev->priv;
	return lb ? lb->room : NULL;
}

static int parse_windows(struct ps_dev *dev, struct lb_input *in, const struct ps_opts *o)
{
	const char *v = ps_opt_get(o, "occupied");
	char *copy, *save = NULL;
	if (!v)
		return 0;
	if (!(copy = strdup(v)))
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	for (char *item = strtok_r(copy, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
		int h1, m1, h2, m2, n = 0;
		if (sscanf(item, " %d:%d-%d:%d %n", &h1, &m1, &h2, &m2, &n) != 4 || item[n] ||
		    in->nwin >= LB_MAX_WINDOWS || h1 < 0 || h1 > 24 || h2 < 0 || h2 > 24 || m1 < 0 || m1 > 59 ||
		    m2 < 0 || m2 > 59) {
			free(copy);
			return ps_dev_fail(dev, EINVAL, "%s:%d: occupied: '%s' is not HH:MM-HH:MM (at most %d)",
			                   o->file, ps_opt_line(o, "occupied"), item, LB_MAX_WINDOWS);
		}
		in->win[in->nwin][0] = h1 * 3600.0 + m1 * 60;
		in->win[in->nwin][1] = h2 * 3600.0 + m2 * 60;
		in->nwin++;
	}
	free(copy);
	return 0;
}

static int lb_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct loopback *lb = dev->priv;
	switch (pt->role) {
	case PS_ROLE_SENSOR:
	case PS_ROLE_TASK_LUX:
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
		if (parse_windows(dev, in, o) != 0)
			return -1;
		pt->priv = in;
		lb->ninput++;
		return 0;
	}
	default:
		return ps_dev_fail(dev, EINVAL, "loopback: no %s points", ps_role_name(pt->role));
	}
}

static int occupied(const struct lb_input *in, double now)
{
	double tod = ps_room_tod(now);
	for (int i = 0; i < in->nwin; i++) {
		double a = in->win[i][0], b = in->win[i][1];
		if (a <= b ? (tod >= a && tod < b) : (tod >= a || tod < b))   /* across midnight */
			return 1;
	}
	return 0;
}

/* The next change of any input after the last service (INFINITY: none). */
static double lb_deadline(struct ps_dev *dev)
{
	struct loopback *lb = dev->priv;
	double next = INFINITY, day0;
	if (!lb || !lb->room || lb->ninput == 0)
		return INFINITY;
	for (int i = 0; i < lb->ninput; i++)
		if (lb->input[i].state < 0)
			return lb->serviced;   /* the first state is reported at once */
	day0 = lb->serviced - ps_room_tod(lb->serviced);
	for (int i = 0; i < lb->ninput; i++)
		for (int w = 0; w < lb->input[i].nwin; w++)
			for (int e = 0; e < 2; e++)
				for (int d = 0; d < 2; d++) {
					double t = day0 + d * 86400.0 + lb->input[i].win[w][e];
					if (t > lb->serviced && t < next)
						next = t;
				}
	return next;
}

static int lb_service(struct ps_dev *dev, double now)
{
	struct loopback *lb = dev->priv;
	if (!lb || !lb->room)
		return 0;
	for (int i = 0; i < lb->ninput; i++) {
		struct lb_input *in = &lb->input[i];
		int st = occupied(in, now);
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

static int lb_read(struct ps_dev *dev, struct ps_point *pt, double now, double *value)
{
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
	if (pt->role == PS_ROLE_RELAY) {
		*value = *(int *)pt->priv;
		return 0;
	}
	if (pt->role == PS_ROLE_INPUT) {
		*value = occupied(pt->priv, now);
		return 0;
	}
	*value = ps_room_output(lb->room, now);
	return 0;
}

static int lb_write(struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
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
	.open = lb_open,
	.add_point = lb_add_point,
	.read = lb_read,
	.write = lb_write,
	.deadline = lb_deadline,
	.service = lb_service,
	.close = lb_close,
};
