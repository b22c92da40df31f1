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
 *  - Time comes in as `now`, seconds on the daemon's clock (monotonic, or
 *    simulated in tests).  Drivers do not read the clock for control timing.
 *  - Failure: return -1 with errno set and a one-line detail in dev->err:
 *      EINVAL   bad option (dev->err is "file:line: key: why")
 *      ENOTSUP  driver not compiled in
 *      ETIMEDOUT no reply in time        EPROTO   garbled or exception reply
 *      ERANGE   reading outside the point's valid range (open circuit, saturation)
 *      ENODEV   device gone (unplugged, connection lost); the driver reconnects
 *               by itself on later calls, with backoff, and succeeds again once
 *               the device is back.
 *    The daemon drives lights to the safe level on any failure and logs dev->err.
 *  - Events from inputs (buttons, occupancy) are delivered through
 *    dev->on_event from inside service().
 */
#ifndef PS_DRIVER_H
#define PS_DRIVER_H

#include <stddef.h>

enum ps_role {
	PS_ROLE_SENSOR = 0,   /* photosensor signal, volts */
	PS_ROLE_TASK_LUX,     /* task illuminance meter, lux */
	PS_ROLE_DIM,          /* dimming output, light-output fraction 0..1 */
	PS_ROLE_RELAY,        /* switched output, 0 or 1 (a step of a stepped system) */
	PS_ROLE_INPUT,        /* button or occupancy input, 0 or 1, reported as events */
	PS_ROLE_COUNT
};

/* Role names as used in the config file ("sensor", "task", "dim", "relay", "input"). */
const char *ps_role_name(int role);
int ps_role_parse(const char *name);   /* -1 if unknown */

/* One configuration option handed to a driver: key, value and where it was
 * written, so a driver's message can name file and line. */
struct ps_opt {
	const char *key;
	const char *value;
	int line;
	int used;             /* set by ps_opt_get; the daemon reports unused keys */
};

struct ps_opts {
	struct ps_opt *v;
	size_t n;
	const char *file;     /* config file name for messages */
};

/* Find an option (marks it used), NULL if absent. */
const char *ps_opt_get(const struct ps_opts *o, const char *key);
/* Typed lookups: 0 ok (absent gives def), -1 with errno EINVAL and a
 * "file:line: key: why" message in err. */
int ps_opt_double(const struct ps_opts *o, const char *key, double def, double min,
                  double max, double *out, char *err, size_t errlen);
int ps_opt_long(const struct ps_opts *o, const char *key, long def, long min, long max,
                long *out, char *err, size_t errlen);
/* names NULL-terminated; *out = index. */
int ps_opt_enum(const struct ps_opts *o, const char *key, const char *const *names, int def,
                int *out, char *err, size_t errlen);
/* Line of an option for messages (0 if absent). */
int ps_opt_line(const struct ps_opts *o, const char *key);

struct ps_dev;
struct ps_point;

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
	const char *summary;  /* one line for --help and man pages */
	int compiled_in;      /* 0 for a stub: every method fails with ENOTSUP */
	/* Parse options, connect.  May succeed while the device is absent (then
	 * reads fail with ENODEV until it appears). */
	int (*open)(struct ps_dev *dev, const struct ps_opts *opts);
	/* Attach a point with its options (address, scaling, ...). */
	int (*add_point)(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *opts);
	/* Read a sensor, lux or input point. */
	int (*read)(struct ps_dev *dev, struct ps_point *pt, double now, double *value);
	/* Command a dim or relay point. */
	int (*write)(struct ps_dev *dev, struct ps_point *pt, double now, double value);
	/* Event-loop hooks, all optional (NULL): a file descriptor to poll for
	 * input (-1 for none), the next time service() is due (INFINITY for
	 * none), and the work to do when either fires. */
	int (*fd)(struct ps_dev *dev);
	double (*deadline)(struct ps_dev *dev);
	int (*service)(struct ps_dev *dev, double now);
	/* Release everything (lines, interfaces, sockets).  Safe after a failed open. */
	void (*close)(struct ps_dev *dev);
};

/* The registry: every driver this build knows, compiled in or not. */
extern const struct ps_driver *const ps_drivers[];
/* Find by name; NULL if no such driver exists at all. */
const struct ps_driver *ps_driver_find(const char *name);

/* Set dev->err (printf-style) and errno; returns -1. */
int ps_dev_fail(struct ps_dev *dev, int err, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

#endif
