/* SPDX-License-Identifier: ISC */
/* One I/O thread per blocking device: the event loop never waits on a
 * device.  A Modbus transaction blocks (libmodbus has no non-blocking
 * call) for up to timeout x (retries + 1), and a connect as long again;
 * with several zones on slow modules the loop would serve the control
 * socket and the watchdog only between them.  Here each such device gets a
 * worker thread that alone calls its driver (read, write, deadline,
 * service: the driver's contract is unchanged, one caller at a time), and
 * the loop trades requests and results with it under a mutex, woken by an
 * eventfd in its poll set.
 *
 * Reads: the engine asks (psd_devio_ask) and comes back when woken; a
 * result is taken once (psd_devio_take).  Writes: the latest value per
 * point replaces one not yet sent (lights follow the last command, not a
 * backlog); psd_devio_write returns the outcome of the last write done.
 * Inputs' events from service() are queued and delivered by the loop
 * thread (psd_devio_drain).  All times are the daemon's clock, read by the
 * worker from its own copy of a real clock. */
#ifndef PSD_DEVIO_H
#define PSD_DEVIO_H

#include <stddef.h>

#include "clock.h"
#include "driver.h"

struct psd_devio;

/* Whether a device of this driver is served by a worker (blocking I/O). */
int psd_devio_wanted(const struct ps_driver *drv);
/* Start the worker of dev, whose points are pts[0..npts) (the engine's
 * array; only those of dev are used).  The worker takes dev->on_event and
 * queues the events.  NULL with errno on failure. */
struct psd_devio *psd_devio_start(struct ps_dev *dev, struct ps_point *pts, size_t npts,
                                  const struct psd_clock *clock);
/* Stop and join (waits for a transaction under way), restore dev->on_event. */
void psd_devio_stop(struct psd_devio *io);
/* The descriptor the loop polls: readable when a result or event is ready. */
int psd_devio_fd(const struct psd_devio *io);
/* Read the eventfd and deliver queued events through the saved on_event. */
void psd_devio_drain(struct psd_devio *io);

/* Ask for a read of point pt (its index in pts).  0: a result is ready to
 * take; 1: asked (or still under way): come back when woken. */
int psd_devio_ask(struct psd_devio *io, size_t pt, double now);
/* Take the ready result of pt: as the driver's read (0 and *value, or -1
 * with errno and the driver's message in err; dev->err is the worker's).
 * -1 ETIMEDOUT "DRIVER DEVICE: POINT: no reply for N s" when none is ready. */
int psd_devio_take(struct psd_devio *io, size_t pt, double now, double *value, char *err, size_t errlen);
/* Queue a write of value to pt; returns the last finished write's outcome
 * for pt (0, or -1 with errno and the message in err), 0 when none
 * finished yet. */
int psd_devio_write(struct psd_devio *io, size_t pt, double now, double value, char *err, size_t errlen);
/* Seconds the worker has been in its current driver call (0 when idle). */
double psd_devio_busy(const struct psd_devio *io);

#endif
