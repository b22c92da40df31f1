/* SPDX-License-Identifier: ISC */
/* An emulated GPIO chip for tests (the kernel's v1 character-device
 * interface, as libgpiod 1.6 uses it), served by umockdev inside the process
 * under test.  It keeps the kernel's limits: each event line buffers 16
 * events and drops the rest until the reader drains it (counted, as the
 * kernel does not tell).  A pulse generator emits rising edges at a rate in
 * real time, with monotonic timestamps, for light-to-frequency sensors. */
#ifndef PS_VGPIO_H
#define PS_VGPIO_H

#include <stdint.h>

struct vgpio;

/* A chip named name (e.g. "gpiochip0") with nlines lines, in a new umockdev
 * testbed (which sets UMOCKDEV_DIR).  NULL on failure. */
struct vgpio *vgpio_new(const char *name, unsigned nlines);
void vgpio_free(struct vgpio *v);
/* Drive an input line's physical level (an edge event if it changes). */
void vgpio_set(struct vgpio *v, unsigned line, int level);
/* A button press on an input line: `bounces` quick toggles, then held
 * pressed (physical level `pressed`) for hold_ms, then released. */
void vgpio_press(struct vgpio *v, unsigned line, int pressed, int bounces, int hold_ms);
/* Rising edges at hz on a line from now on (0 stops). */
void vgpio_rate(struct vgpio *v, unsigned line, double hz);
/* A TSL230R on a line: hz at divider 1, divided by 1, 2, 10 or 100 as its
 * S2/S3 pins (lines s2, s3, driven by the program) say. */
void vgpio_tsl230(struct vgpio *v, unsigned line, double hz, unsigned s2, unsigned s3);
/* Physical level of a line, and whether a program holds it. */
int vgpio_level(struct vgpio *v, unsigned line);
int vgpio_held(struct vgpio *v, unsigned line);
/* Events the 16-event buffer dropped on a line. */
unsigned long vgpio_dropped(struct vgpio *v, unsigned line);
/* "line L level V held H dropped D" lines into buf. */
void vgpio_dump(struct vgpio *v, char *buf, unsigned len);

#endif
