/* SPDX-License-Identifier: ISC */
/* The one way a driver fails (dev->err and errno), what a failure means to
 * the daemon, and a driver's check method run for its own open. */
#ifndef PS_DEV_H
#define PS_DEV_H

struct ps_dev;
struct ps_opts;

/* Set dev->err (printf-style) and errno; returns -1. */
int ps_dev_fail(struct ps_dev *dev, int err, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));
/* What a failed read's errno means: 1 a fault at once (ENODEV, ENOTSUP,
 * EINVAL, ERANGE, EOVERFLOW: the device is gone or misconfigured, or the
 * value is wrong), 0 a missed reply (ETIMEDOUT, EPROTO, EAGAIN, ...: a
 * fault only once the last good reading is older than the zone's
 * stale_after; until then the level is held). */
int ps_dev_fault_at_once(int err);
/* The driver's check method on a section, for its own open (role < 0) and
 * add_point: -1 with errno EINVAL and "file:line: why" in dev->err. */
int ps_dev_check(struct ps_dev *dev, const struct ps_opts *o, int role);

#endif
