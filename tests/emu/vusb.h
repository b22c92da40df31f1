/* SPDX-License-Identifier: ISC */
/* vusb: an emulated USB device node for real libusb-1.0, on libumockdev.
 * How it works is doc/emulation.md section 2 (an approach first tried in a
 * throw-away prototype before this project):
 * libusb's usbfs ioctls on /dev/bus/usb/BBB/DDD are served by a handler in
 * umockdev's worker thread of THIS process; in a child process started from
 * here they arrive over umockdev's socket.  The process (and its children)
 * must run with libumockdev-preload.so.0 preloaded.
 *
 * Added for the DALI tests: several devices in one testbed at different ports
 * with their own serial numbers, and unplugging (pending transfers end with
 * -ESHUTDOWN, every later ioctl fails with ENODEV, the device leaves sysfs). */
#ifndef PS_VUSB_H
#define PS_VUSB_H

#include <stddef.h>
#include <stdint.h>

struct vusb;
typedef struct _UMockdevTestbed UMockdevTestbed;

/* Called in the umockdev worker thread for every OUT interrupt or bulk
 * transfer; may call vusb_queue_in().  Must not block. */
typedef void (*vusb_out_fn)(struct vusb *dev, uint8_t ep, const uint8_t *data, size_t len, void *user);

struct vusb_desc {
	uint16_t vid, pid;
	int port;                 /* 1.. : sysfs 1-<port> */
	int devnum;               /* 2.. : /dev/bus/usb/001/<devnum>; new on every plug */
	const char *serial;       /* iSerialNumber string */
	int report_len;           /* wMaxPacketSize of both endpoints */
	uint8_t ep_out;           /* the OUT endpoint's address; 0: 0x02 (the IN one is 0x81) */
	const char *maker, *product;   /* string descriptors 1 and 2; NULL: the DALI USB's */
};

/* NULL with a message in err on failure. */
struct vusb *vusb_new(UMockdevTestbed *tb, const struct vusb_desc *desc, vusb_out_fn cb, void *user,
                      char *err, size_t errlen);
void vusb_free(struct vusb *dev);

/* Queue a report for the next IN transfer (thread safe). */
void vusb_queue_in(struct vusb *dev, const uint8_t *data, size_t len);
/* Unplug: fail pending transfers, leave sysfs; the object stays valid. */
void vusb_unplug(struct vusb *dev);
int vusb_is_gone(struct vusb *dev);
/* 1 while an IN transfer waits for data (the host listens). */
int vusb_in_waiting(struct vusb *dev);
unsigned vusb_ioctl_count(struct vusb *dev);

#endif
