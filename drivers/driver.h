/* SPDX-License-Identifier: ISC */
/* The driver interface: one small table of methods per driver, one file per
 * driver, all registered in drivers/registry.c.
 *
 * A device (struct ps_dev) is one connection: a Modbus TCP module, a DALI USB
 * interface, a GPIO chip, the loopback room.  A point (struct ps_point) is one
 * value on it with a role: the photosensor's volts, a task meter's lux, a
 * dimming output, a relay, a button.  Several points share one device.
 *
 * Contract (the daemon core relies on every item):
 *  - Drivers never sleep, never exit, never print.  Blocking I/O is bounded
 *    by the driver's own short timeout (tens of ms); anything longer is split
 *    into steps driven by deadline()/service().
 *  - Time comes in on two clocks, and drivers read neither themselves:
 *    `now`, seconds on the daemon's clock (the room's time of day: monotonic,
 *    sped up with psensd -x, or simulated in tests), for what belongs to the
 *    room and its control (an event's time, a simulated room's day, a
 *    Modbus poll period); and `mono`, CLOCK_MONOTONIC seconds, never scaled,
 *    for what belongs to a wire (a reply timeout, a frame gap, a retry's
 *    back-off, a DALI sensor's report age): a bus runs at its own speed
 *    however fast the room's clock runs.  A test may pass the same value for
 *    both.
 *  - Failure: return -1 with errno set and a one-line detail in dev->err
 *    (ps_dev_fail does both):
 *      EINVAL   bad option (dev->err is "file:line: key: why")
 *      ENOTSUP  driver not compiled in
 *      ETIMEDOUT no reply in time        EPROTO   garbled or exception reply
 *      EAGAIN   busy (a queue full): asked again later
 *      ERANGE   reading outside the point's valid range (open circuit, saturation)
 *      EOVERFLOW a counting sensor lost events: its value would read low
 *      ENODEV   device gone (unplugged, connection lost); the driver reconnects
 *               by itself on later calls, with backoff, and succeeds again once
 *               the device is back.
 *    ps_dev_fault_at_once() says which of these are a fault at once and which
 *    a missed reply; the daemon drives the lights to the safe level on a
 *    fault and logs dev->err.
 *  - Events from inputs (buttons, occupancy) are delivered through
 *    dev->on_event from inside service().
 */
#ifndef PS_DRIVER_H
#define PS_DRIVER_H

#include <stddef.h>

#include "dev.h"
#include "opts.h"
#include "role.h"

struct ps_dev;
struct ps_point;
struct ps_room_params;   /* drivers/room.h: a simulated room's day and responses */

/* What is true in a simulated room at a time (the truth hook): what a
 * summary or a status compares the control's estimate with. */
struct ps_truth {
	double task_lux;      /* true task illuminance, no noise, no fault */
	double output;        /* the lamps' light output, 0..1 */
	double energy;        /* integral of the output since the room was set up, fraction x s */
	double daylight_v;    /* daylight part of the sensor signal, volts */
	double daylight_lux;  /* daylight part of the task illuminance */
	const char *fault;    /* the simulated fault active now, by its name in the
	                         device's faults key ("drop", "late", "open", ...);
	                         NULL for none */
};

typedef void (*ps_event_fn)(void *user, struct ps_dev *dev, struct ps_point *pt,
                            double now, double value);

struct ps_point {
	char name[48];
	int role;             /* enum ps_role */
	void *priv;           /* driver's per-point state */
};

struct ps_dev {
	const struct ps_driver *drv;
	char name[48];
	void *priv;           /* driver's per-device state */
	char err[256];        /* detail of the last failure */
	ps_event_fn on_event; /* set by the daemon before open; may be NULL */
	void *event_user;
};

struct ps_driver {
	const char *name;
	const char *summary;  /* one line for psensd -h and -L */
	int compiled_in;      /* 0 for a stub: every method fails with ENOTSUP */
	/* The keys it takes (opts.h), NULL-key terminated; NULL for a stub. */
	const struct ps_opts_spec *options;
	/* Checks across keys the table cannot express (e.g. a Modbus device needs
	 * host or device), on a device section (role < 0) or a point section
	 * whose keys passed the table; NULL if none.  -1 with the key's line in
	 * *line and why (no location).  Pure: no I/O, so psensd -n runs it. */
	int (*check)(const struct ps_opts *opts, int role, int *line, char *why, size_t n);
	/* Parse options, connect.  May succeed while the device is absent (then
	 * reads fail with ENODEV until it appears). */
	int (*open)(struct ps_dev *dev, const struct ps_opts *opts);
	/* Attach a point with its options (address, scaling, ...). */
	int (*add_point)(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *opts);
	/* Read a sensor, lux or input point. */
	int (*read)(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *value);
	/* Command a dim or relay point. */
	int (*write)(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double value);
	/* Event-loop hooks, all optional (NULL): a file descriptor to poll for
	 * input (-1 for none), the next time service() is due (INFINITY for
	 * none), and the work to do when either fires.  deadline returns the
	 * due time on the daemon's clock; *mono comes in INFINITY and a driver
	 * timing a wire lowers it to its due time on the monotonic clock:
	 * service() is due when either is reached. */
	int (*fd)(struct ps_dev *dev);
	double (*deadline)(struct ps_dev *dev, double *mono);
	int (*service)(struct ps_dev *dev, double now, double mono);
	/* Release everything (lines, interfaces, sockets).  Safe after a failed open. */
	void (*close)(struct ps_dev *dev);
	/* Simulated devices only, NULL for hardware.  setup: give an opened
	 * device its room, built by the daemon from the scene's results
	 * (daemon/roomsetup.c); the device's own options are merged in.  Called
	 * once after open, before add_point.  truth: what is true in the room
	 * at now, without advancing it (any time, even ahead of its clock). */
	int (*setup)(struct ps_dev *dev, const struct ps_room_params *room, double now);
	int (*truth)(struct ps_dev *dev, double now, struct ps_truth *t);
	/* Optional (NULL): a request for the device itself from the control
	 * socket, e.g. DALI commissioning (psensctl dali DEVICE scan).  words
	 * are the request after the device's name; pts are points of this
	 * device the daemon resolved for it (a zone's outputs), npts may be 0.
	 * Work longer than a moment runs step-wise from service(); the reply,
	 * one JSON object, goes to out.  0 ok; -1 with errno and dev->err
	 * (EINVAL a bad request, EBUSY other work runs, ENODEV the device is
	 * gone). */
	int (*command)(struct ps_dev *dev, int nwords, char **words, struct ps_point *const *pts, int npts,
	               double now, double mono, char *out, size_t outlen);
	/* Optional (NULL): the full scale of a reading point, the largest value
	 * its input can give as the driver scales it (an analog input's top
	 * code, a light-to-frequency sensor's saturation, a simulated sensor's
	 * clipping): a reading at it says only "this much or more".  0 with
	 * *limit; -1 when the point has none (an output, a float register with
	 * no stated range).  Pure: no I/O. */
	int (*full_scale)(struct ps_dev *dev, struct ps_point *pt, double *limit);
	/* Optional (NULL: every read() measures anew).  For a reading point
	 * whose value the device sends by itself, a DALI-2 sensor's events and
	 * periodic reports, read() gives the last value that came, and between
	 * them the truth may drift (up to the sensor's hysteresis).  age: the
	 * seconds on the monotonic clock since that value was measured (0 for
	 * a point read anew at each read(); INFINITY none yet).  refresh: a
	 * value measured from mono on is wanted; the driver asks the device as
	 * soon as the wire allows and hands the answer to on_event, even when
	 * it has not changed.  Both pure of I/O but for queueing the request;
	 * 0, or -1 with errno (EINVAL a point that cannot). */
	double (*age)(struct ps_dev *dev, struct ps_point *pt, double mono);
	int (*refresh)(struct ps_dev *dev, struct ps_point *pt, double now, double mono);
};

/* Judge a device section (role < 0) or a point section: every key against
 * the driver's table, then, when they all pass, its check method.  Each
 * error goes to report (opts.h); returns the number of errors.  A stub
 * (not compiled in) has no table: its keys are not judged. */
int ps_driver_check(const struct ps_driver *drv, const struct ps_opts *o, int role, ps_opts_report_fn report,
                    void *user);

#endif
