/* SPDX-License-Identifier: ISC */
/* The DALI USB driver, ps_driver_dali_usb, and its extras beyond the
 * driver.h table: counters for tests, benchmarks and psensctl, and the last
 * commissioning job. */
#ifndef PS_DALI_USB_H
#define PS_DALI_USB_H

#include "driver.h"

struct ps_dali_usb_stats {
	unsigned long frames;       /* SEND reports written (retries included) */
	unsigned long retries;      /* frames sent again after a timeout or garbled answer */
	unsigned long timeouts;     /* transactions that hit the reply timeout */
	unsigned long garbled;      /* bus errors and malformed reports */
	unsigned long failed;       /* transactions given up after all retries */
	unsigned long connects;     /* successful connects (1 + replugs) */
	unsigned long stray;        /* reports for no outstanding sequence number */
	unsigned long collisions;   /* our frames that collided with another master's */
	unsigned long input_frames; /* transactions for control devices' inputs (configuration, polls) */
	unsigned long events;       /* control devices' event messages taken by an input point */
	int connected;              /* 1 while the interface is claimed */
	int pending;                /* transactions queued or in flight */
	int job_running;            /* a commissioning job runs */
	int firmware;               /* the interface's firmware version, major << 8 | minor; -1 unknown */
};

/* 0, or -1 (EINVAL) when dev is not a dali_usb device. */
int ps_dali_usb_stats(struct ps_dev *dev, struct ps_dali_usb_stats *st);

extern const struct ps_driver ps_driver_dali_usb;

struct ps_dali_commission;
/* The last commissioning job (dali_commission.h), NULL before the first. */
const struct ps_dali_commission *ps_dali_usb_job(struct ps_dev *dev);

#endif
