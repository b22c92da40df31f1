/* SPDX-License-Identifier: ISC */
/* vusb: see vusb.h.  Only what libusb-1.0 (1.0.26) needs for a HID-class
 * device with one interrupt IN and one interrupt OUT endpoint. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>          /* before usbdevice_fs.h, which needs _IOR */
#include <sys/stat.h>
#include <unistd.h>
#include <linux/usbdevice_fs.h>
#include <umockdev.h>

#include "vusb.h"

struct urb_rec {
	gulong urb_addr;        /* the client's struct usbdevfs_urb */
	uint8_t type, ep;
	int buffer_length;
	int status, actual_length;
	size_t data_off;        /* 8 for control transfers: setup packet first */
	uint8_t *data;          /* device -> host payload written at reap time */
};

struct vusb {
	UMockdevTestbed *tb;
	UMockdevIoctlBase *handler;
	GMutex lock;
	GQueue in_urbs, done, in_data;
	gboolean driver_bound, gone;
	UMockdevIoctlClient *claimed_by;   /* the connection holding interface 0, as usbfs tracks it */
	int gate_fd;
	vusb_out_fn cb;
	void *user;
	unsigned n_ioctl;
	struct vusb_desc desc;
	char serial[64];
	char devnode[64], syspath[128];
	uint8_t dev_desc[18], cfg_desc[41];
};

static const uint8_t hid_report_desc[] = {
	0x06, 0x00, 0xFF, 0x09, 0x01, 0xA1, 0x01, 0x15, 0x00, 0x26, 0xFF, 0x00,
	0x75, 0x08, 0x95, 0x40, 0x09, 0x01, 0x81, 0x02, 0x95, 0x40, 0x09, 0x01,
	0x91, 0x02, 0xC0 };

static void build_descriptors(struct vusb *d)
{
	uint16_t vid = d->desc.vid, pid = d->desc.pid;
	uint8_t mps = (uint8_t)d->desc.report_len;
	uint8_t ep_out = d->desc.ep_out ? d->desc.ep_out : 0x02;
	const uint8_t dev[18] = { 18, 1, 0x10, 0x01, 0, 0, 0, 8, vid & 0xff, vid >> 8, pid & 0xff, pid >> 8,
		                  0x00, 0x01, 1, 2, 3, 1 };
	const uint8_t cfg[41] = {
		9, 2, 41, 0, 1, 1, 0, 0x80, 5,                              /* configuration */
		9, 4, 0, 0, 2, 3, 0, 0, 0,                                  /* interface 0, HID */
		9, 0x21, 0x11, 0x01, 0, 1, 0x22, sizeof hid_report_desc, 0,
		7, 5, 0x81, 3, mps, 0, 1,                                   /* EP1 IN interrupt */
		7, 5, ep_out, 3, mps, 0, 1 };                               /* OUT interrupt */
	memcpy(d->dev_desc, dev, sizeof dev);
	memcpy(d->cfg_desc, cfg, sizeof cfg);
}

static size_t string_desc(struct vusb *d, unsigned idx, uint8_t *out)
{
	const char *s[] = { NULL, d->desc.maker ? d->desc.maker : "Lunatone (emulated)",
		            d->desc.product ? d->desc.product : "DALI USB (emulated)", d->serial };
	size_t n;
	if (idx == 0) {
		out[0] = 4; out[1] = 3; out[2] = 0x09; out[3] = 0x04;
		return 4;
	}
	if (idx >= 4)
		return 0;
	n = strlen(s[idx]);
	out[0] = (uint8_t)(2 + 2 * n);
	out[1] = 3;
	for (size_t i = 0; i < n; i++) {
		out[2 + 2 * i] = (uint8_t)s[idx][i];
		out[3 + 2 * i] = 0;
	}
	return 2 + 2 * n;
}

/* The node is a FIFO shared with libusb's fd.  usbfs signals "URB completed"
 * with POLLOUT; keeping the one-page pipe full while nothing is reapable
 * makes libusb's poll() sleep instead of spinning (doc/emulation.md 2.2).
 * Caller holds the lock. */
static void gate_update_locked(struct vusb *d)
{
	char buf[64];
	if (d->gate_fd < 0)
		return;
	while (read(d->gate_fd, buf, sizeof buf) > 0) {
	}
	if (g_queue_is_empty(&d->done))
		(void)!write(d->gate_fd, "x", 1);
}

static void match_in_locked(struct vusb *d)
{
	while (!g_queue_is_empty(&d->in_urbs) && !g_queue_is_empty(&d->in_data)) {
		struct urb_rec *r = g_queue_pop_head(&d->in_urbs);
		GBytes *b = g_queue_pop_head(&d->in_data);
		gsize n;
		const uint8_t *p = g_bytes_get_data(b, &n);
		if ((int)n > r->buffer_length)
			n = (gsize)r->buffer_length;
		r->data = g_memdup2(p, n ? n : 1);
		r->actual_length = (int)n;
		r->status = 0;
		g_bytes_unref(b);
		g_queue_push_tail(&d->done, r);
	}
	gate_update_locked(d);
}

void vusb_queue_in(struct vusb *d, const uint8_t *data, size_t len)
{
	g_mutex_lock(&d->lock);
	if (!d->gone) {
		g_queue_push_tail(&d->in_data, g_bytes_new(data, len));
		match_in_locked(d);
	}
	g_mutex_unlock(&d->lock);
}

int vusb_in_waiting(struct vusb *d)
{
	int w;
	g_mutex_lock(&d->lock);
	w = !d->gone && !g_queue_is_empty(&d->in_urbs);
	g_mutex_unlock(&d->lock);
	return w;
}

unsigned vusb_ioctl_count(struct vusb *d)
{
	return (unsigned)g_atomic_int_get(&d->n_ioctl);
}

int vusb_is_gone(struct vusb *d)
{
	int g;
	g_mutex_lock(&d->lock);
	g = d->gone;
	g_mutex_unlock(&d->lock);
	return g;
}

void vusb_unplug(struct vusb *d)
{
	g_mutex_lock(&d->lock);
	if (d->gone) {
		g_mutex_unlock(&d->lock);
		return;
	}
	d->gone = TRUE;
	/* what the kernel does on disconnect: pending URBs end with -ESHUTDOWN */
	while (!g_queue_is_empty(&d->in_urbs)) {
		struct urb_rec *r = g_queue_pop_head(&d->in_urbs);
		r->status = -ESHUTDOWN;
		r->actual_length = 0;
		g_queue_push_tail(&d->done, r);
	}
	g_queue_clear_full(&d->in_data, (GDestroyNotify)g_bytes_unref);
	gate_update_locked(d);
	g_mutex_unlock(&d->lock);
	umockdev_testbed_uevent(d->tb, d->syspath, "remove");
	umockdev_testbed_remove_device(d->tb, d->syspath);
}

static void do_control(struct vusb *d, struct urb_rec *r, const uint8_t *buf)
{
	uint8_t bm = buf[0], req = buf[1], tmp[256];
	uint16_t wValue = (uint16_t)(buf[2] | buf[3] << 8), wLength = (uint16_t)(buf[6] | buf[7] << 8);
	size_t n = 0;
	r->data_off = 8;
	r->status = 0;
	if (bm == 0x80 && req == 6) {                                /* GET_DESCRIPTOR */
		switch (wValue >> 8) {
		case 1: memcpy(tmp, d->dev_desc, n = sizeof d->dev_desc); break;
		case 2: memcpy(tmp, d->cfg_desc, n = sizeof d->cfg_desc); break;
		case 3: n = string_desc(d, wValue & 0xff, tmp); break;
		}
		if (!n)
			r->status = -EPIPE;
	} else if (bm == 0x81 && req == 6 && (wValue >> 8) == 0x22) {
		memcpy(tmp, hid_report_desc, n = sizeof hid_report_desc);
	} else if (bm == 0x21) {                                     /* HID class OUT */
		r->actual_length = wLength;
		return;
	} else {
		r->status = -EPIPE;                                  /* STALL */
	}
	if (n > wLength)
		n = wLength;
	r->actual_length = r->status ? 0 : (int)n;
	if (n)
		r->data = g_memdup2(tmp, n);
}

static void complete(UMockdevIoctlClient *c, int ret, int err)
{
	umockdev_ioctl_client_complete(c, ret, err);
}

/* The claiming connection closed (its process exited or closed the device):
 * the kernel releases its interfaces. */
static void claim_gone(gpointer user, GObject *was)
{
	struct vusb *d = user;
	g_mutex_lock(&d->lock);
	if ((GObject *)d->claimed_by == was)
		d->claimed_by = NULL;
	g_mutex_unlock(&d->lock);
}

/* CLAIMINTERFACE / RELEASEINTERFACE of interface 0 by client: 0 or an errno.
 * A second connection's claim fails with EBUSY, as usbfs does. */
static int claim(struct vusb *d, UMockdevIoctlClient *client, int take)
{
	int rc = 0;
	g_mutex_lock(&d->lock);
	if (take && d->driver_bound) {
		rc = EBUSY;
	} else if (take && d->claimed_by && d->claimed_by != client) {
		rc = EBUSY;
	} else if (take && !d->claimed_by) {
		d->claimed_by = client;
		g_object_weak_ref(G_OBJECT(client), claim_gone, d);
	} else if (!take && d->claimed_by == client) {
		g_object_weak_unref(G_OBJECT(client), claim_gone, d);
		d->claimed_by = NULL;
	}
	g_mutex_unlock(&d->lock);
	return rc;
}

static gboolean submit_urb(struct vusb *d, UMockdevIoctlClient *client, UMockdevIoctlData *arg)
{
	GError *err = NULL;
	UMockdevIoctlData *ud = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_urb), &err), *bd = NULL;
	struct usbdevfs_urb *u;
	struct urb_rec *r;
	if (!ud) {
		g_clear_error(&err);
		complete(client, -1, EFAULT);
		return TRUE;
	}
	u = (struct usbdevfs_urb *)ud->data;
	if (u->buffer_length > 0 && (u->type == USBDEVFS_URB_TYPE_CONTROL || !(u->endpoint & 0x80))) {
		bd = umockdev_ioctl_data_resolve(ud, G_STRUCT_OFFSET(struct usbdevfs_urb, buffer),
		                                 (gsize)u->buffer_length, &err);
		if (!bd) {
			g_clear_error(&err);
			g_object_unref(ud);
			complete(client, -1, EFAULT);
			return TRUE;
		}
	}
	if (u->type == USBDEVFS_URB_TYPE_CONTROL && (!bd || u->buffer_length < 8)) {
		if (bd)
			g_object_unref(bd);
		g_object_unref(ud);
		complete(client, -1, EINVAL);
		return TRUE;
	}
	r = g_new0(struct urb_rec, 1);
	r->urb_addr = ud->client_addr;
	r->type = u->type;
	r->ep = u->endpoint;
	r->buffer_length = u->buffer_length;
	g_mutex_lock(&d->lock);
	if (d->gone) {
		g_mutex_unlock(&d->lock);
		g_free(r);
		if (bd)
			g_object_unref(bd);
		g_object_unref(ud);
		complete(client, -1, ENODEV);
		return TRUE;
	}
	if (u->type == USBDEVFS_URB_TYPE_CONTROL) {
		do_control(d, r, bd->data);
		g_queue_push_tail(&d->done, r);
		gate_update_locked(d);
		g_mutex_unlock(&d->lock);
	} else if (u->endpoint & 0x80) {
		g_queue_push_tail(&d->in_urbs, r);
		match_in_locked(d);
		g_mutex_unlock(&d->lock);
	} else {
		uint8_t *copy = bd ? g_memdup2(bd->data, (gsize)r->buffer_length) : NULL;
		r->actual_length = r->buffer_length;
		g_queue_push_tail(&d->done, r);
		gate_update_locked(d);
		g_mutex_unlock(&d->lock);
		/* the "firmware" runs outside the lock: it queues replies */
		if (d->cb)
			d->cb(d, r->ep, copy, (size_t)r->buffer_length, d->user);
		g_free(copy);
	}
	if (bd)
		g_object_unref(bd);
	g_object_unref(ud);
	complete(client, 0, 0);
	return TRUE;
}

static gboolean reap_urb(struct vusb *d, UMockdevIoctlClient *client, UMockdevIoctlData *arg)
{
	GError *err = NULL;
	UMockdevIoctlData *pd, *ud;
	struct usbdevfs_urb *u;
	struct urb_rec *r;
	int gone;
	g_mutex_lock(&d->lock);
	r = g_queue_pop_head(&d->done);
	gone = d->gone;
	gate_update_locked(d);
	g_mutex_unlock(&d->lock);
	if (!r) {
		complete(client, -1, gone ? ENODEV : EAGAIN);
		return TRUE;
	}
	/* arg points to the client's "struct usbdevfs_urb *" variable */
	pd = umockdev_ioctl_data_resolve(arg, 0, sizeof(gulong), &err);
	if (!pd)
		goto fault;
	*(gulong *)pd->data = r->urb_addr;
	ud = umockdev_ioctl_data_resolve(pd, 0, sizeof(struct usbdevfs_urb), &err);
	if (!ud) {
		g_object_unref(pd);
		goto fault;
	}
	u = (struct usbdevfs_urb *)ud->data;
	u->status = r->status;
	u->actual_length = r->actual_length;
	if (r->data && r->actual_length > 0) {
		UMockdevIoctlData *bd = umockdev_ioctl_data_resolve(ud, G_STRUCT_OFFSET(struct usbdevfs_urb, buffer),
		                                                    r->data_off + (gsize)r->actual_length, &err);
		if (bd) {
			memcpy(bd->data + r->data_off, r->data, (size_t)r->actual_length);
			g_object_unref(bd);
		} else {
			g_clear_error(&err);
		}
	}
	g_object_unref(ud);
	g_object_unref(pd);
	g_free(r->data);
	g_free(r);
	complete(client, 0, 0);
	return TRUE;
fault:
	g_clear_error(&err);
	g_free(r->data);
	g_free(r);
	complete(client, -1, EFAULT);
	return TRUE;
}

static gboolean on_ioctl(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer user)
{
	struct vusb *d = user;
	gulong req = umockdev_ioctl_client_get_request(client);
	UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
	GError *err = NULL;
	(void)h;
	g_atomic_int_inc(&d->n_ioctl);

	if (req == USBDEVFS_SUBMITURB)
		return submit_urb(d, client, arg);
	if (req == USBDEVFS_REAPURBNDELAY || req == USBDEVFS_REAPURB)
		return reap_urb(d, client, arg);
	if (req == USBDEVFS_DISCARDURB) {
		gulong addr = *(gulong *)arg->data;
		int found = 0;
		g_mutex_lock(&d->lock);
		for (GList *l = d->in_urbs.head; l; l = l->next) {
			struct urb_rec *r = l->data;
			if (r->urb_addr == addr) {
				g_queue_delete_link(&d->in_urbs, l);
				r->status = -ENOENT;
				r->actual_length = 0;
				g_queue_push_tail(&d->done, r);
				found = 1;
				break;
			}
		}
		gate_update_locked(d);
		g_mutex_unlock(&d->lock);
		complete(client, found ? 0 : -1, found ? 0 : EINVAL);
		return TRUE;
	}
	if (vusb_is_gone(d)) {
		complete(client, -1, ENODEV);
		return TRUE;
	}
	if (req == USBDEVFS_GET_CAPABILITIES) {
		UMockdevIoctlData *cd = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), &err);
		if (!cd) {
			g_clear_error(&err);
			complete(client, -1, EFAULT);
			return TRUE;
		}
		*(guint32 *)cd->data = USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
		                       USBDEVFS_CAP_REAP_AFTER_DISCONNECT;
		g_object_unref(cd);
		complete(client, 0, 0);
		return TRUE;
	}
	if (req == USBDEVFS_GETDRIVER) {
		UMockdevIoctlData *gd = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_getdriver), &err);
		struct usbdevfs_getdriver *g;
		if (!gd) {
			g_clear_error(&err);
			complete(client, -1, EFAULT);
			return TRUE;
		}
		g = (void *)gd->data;
		if (g->interface == 0 && (d->driver_bound || d->claimed_by)) {
			/* a program's claim shows as the usbfs driver (libusb: not a kernel driver) */
			snprintf(g->driver, sizeof g->driver, "%s", d->driver_bound ? "usbhid" : "usbfs");
			complete(client, 0, 0);
		} else {
			complete(client, -1, ENODATA);
		}
		g_object_unref(gd);
		return TRUE;
	}
	if (req == USBDEVFS_IOCTL) {                         /* DISCONNECT / CONNECT the kernel driver */
		UMockdevIoctlData *id = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_ioctl), &err);
		struct usbdevfs_ioctl *io;
		int ok;
		if (!id) {
			g_clear_error(&err);
			complete(client, -1, EFAULT);
			return TRUE;
		}
		io = (void *)id->data;
		ok = io->ifno == 0;
		if (ok && io->ioctl_code == (int)USBDEVFS_DISCONNECT) {
			ok = d->driver_bound;
			d->driver_bound = FALSE;
		} else if (ok && io->ioctl_code == (int)USBDEVFS_CONNECT) {
			d->driver_bound = TRUE;
		}
		g_object_unref(id);
		complete(client, ok ? 0 : -1, ok ? 0 : ENODATA);
		return TRUE;
	}
	if (req == USBDEVFS_DISCONNECT_CLAIM) {
		UMockdevIoctlData *cd = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_disconnect_claim), &err);
		int ok;
		if (!cd) {
			g_clear_error(&err);
			complete(client, -1, EFAULT);
			return TRUE;
		}
		ok = ((struct usbdevfs_disconnect_claim *)(void *)cd->data)->interface == 0;
		g_object_unref(cd);
		if (!ok) {
			complete(client, -1, EINVAL);
			return TRUE;
		}
		g_mutex_lock(&d->lock);
		if (!d->claimed_by)
			d->driver_bound = FALSE;
		g_mutex_unlock(&d->lock);
		ok = claim(d, client, 1);
		complete(client, ok ? -1 : 0, ok);
		return TRUE;
	}
	if (req == USBDEVFS_CLAIMINTERFACE || req == USBDEVFS_RELEASEINTERFACE) {
		UMockdevIoctlData *cd = umockdev_ioctl_data_resolve(arg, 0, sizeof(unsigned int), &err);
		unsigned ifno;
		if (!cd) {
			g_clear_error(&err);
			complete(client, -1, EFAULT);
			return TRUE;
		}
		ifno = *(unsigned *)cd->data;
		g_object_unref(cd);
		if (ifno != 0) {
			complete(client, -1, EINVAL);
		} else {
			int rc = claim(d, client, req == USBDEVFS_CLAIMINTERFACE);
			complete(client, rc ? -1 : 0, rc);
		}
		return TRUE;
	}
	if (req == USBDEVFS_RESET || req == USBDEVFS_CLEAR_HALT || req == USBDEVFS_SETINTERFACE ||
	    req == USBDEVFS_SETCONFIGURATION || req == USBDEVFS_RESETEP) {
		complete(client, 0, 0);
		return TRUE;
	}
	complete(client, -1, ENOTTY);
	return TRUE;
}

static char *hex(const uint8_t *p, size_t n)
{
	GString *s = g_string_new(NULL);
	for (size_t i = 0; i < n; i++)
		g_string_append_printf(s, "%02X", p[i]);
	return g_string_free(s, FALSE);
}

struct vusb *vusb_new(UMockdevTestbed *tb, const struct vusb_desc *desc, vusb_out_fn cb, void *user,
                      char *errbuf, size_t errlen)
{
	struct vusb *d = g_new0(struct vusb, 1);
	uint8_t all[18 + 41];
	GError *err = NULL;
	char *h, *text, *root, *node;
	g_mutex_init(&d->lock);
	d->desc = *desc;
	snprintf(d->serial, sizeof d->serial, "%s", desc->serial ? desc->serial : "");
	d->desc.serial = d->serial;
	d->cb = cb;
	d->user = user;
	d->driver_bound = TRUE;   /* usbhid binds a HID device first */
	d->gate_fd = -1;
	build_descriptors(d);
	snprintf(d->devnode, sizeof d->devnode, "/dev/bus/usb/001/%03d", desc->devnum);
	snprintf(d->syspath, sizeof d->syspath, "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-%d", desc->port);
	memcpy(all, d->dev_desc, 18);
	memcpy(all + 18, d->cfg_desc, 41);
	h = hex(all, sizeof all);
	text = g_strdup_printf("P: /devices/pci0000:00/0000:00:14.0/usb1/1-%d\n"
	                       "N: bus/usb/001/%03d\n"
	                       "E: SUBSYSTEM=usb\n"
	                       "E: DEVTYPE=usb_device\n"
	                       "E: DRIVER=usb\n"
	                       "E: DEVNAME=/dev/bus/usb/001/%03d\n"
	                       "E: BUSNUM=001\n"
	                       "E: DEVNUM=%03d\n"
	                       "E: MAJOR=189\n"
	                       "E: MINOR=%d\n"
	                       "A: busnum=1\\n\n"
	                       "A: devnum=%d\\n\n"
	                       "A: speed=12\\n\n"
	                       "A: bConfigurationValue=1\\n\n"
	                       "A: bNumConfigurations=1\\n\n"
	                       "A: idVendor=%04x\\n\n"
	                       "A: idProduct=%04x\\n\n"
	                       "A: serial=%s\\n\n"
	                       "A: dev=189:%d\\n\n"
	                       "H: descriptors=%s\n",
	                       desc->port, desc->devnum, desc->devnum, desc->devnum, desc->devnum - 1,
	                       desc->devnum, desc->vid, desc->pid, d->serial, desc->devnum - 1, h);
	g_free(h);
	d->tb = g_object_ref(tb);
	if (!umockdev_testbed_add_from_string(d->tb, text, &err)) {
		snprintf(errbuf, errlen, "umockdev: %s", err->message);
		g_clear_error(&err);
		g_free(text);
		vusb_free(d);
		return NULL;
	}
	g_free(text);
	/* the node file becomes a FIFO: the gate of doc/emulation.md 2.2 */
	root = umockdev_testbed_get_root_dir(d->tb);
	node = g_build_filename(root, d->devnode, NULL);
	if (unlink(node) != 0 || mkfifo(node, 0666) != 0 ||
	    (d->gate_fd = open(node, O_RDWR | O_NONBLOCK | O_CLOEXEC)) < 0) {
		snprintf(errbuf, errlen, "cannot make the FIFO gate %s: %s", node, g_strerror(errno));
		g_free(node);
		g_free(root);
		vusb_free(d);
		return NULL;
	}
	fcntl(d->gate_fd, F_SETPIPE_SZ, 4096);
	g_mutex_lock(&d->lock);
	gate_update_locked(d);
	g_mutex_unlock(&d->lock);
	g_free(node);
	g_free(root);
	d->handler = umockdev_ioctl_base_new();
	g_signal_connect(d->handler, "handle-ioctl", G_CALLBACK(on_ioctl), d);
	if (!umockdev_testbed_attach_ioctl(d->tb, d->devnode, d->handler, &err)) {
		snprintf(errbuf, errlen, "umockdev attach_ioctl: %s", err->message);
		g_clear_error(&err);
		vusb_free(d);
		return NULL;
	}
	return d;
}

void vusb_free(struct vusb *d)
{
	GError *err = NULL;
	if (!d)
		return;
	if (d->claimed_by)
		g_object_weak_unref(G_OBJECT(d->claimed_by), claim_gone, d);
	if (d->handler) {
		umockdev_testbed_detach_ioctl(d->tb, d->devnode, &err);
		g_clear_error(&err);
		g_object_unref(d->handler);
	}
	if (d->tb)
		g_object_unref(d->tb);
	g_queue_clear_full(&d->in_data, (GDestroyNotify)g_bytes_unref);
	while (!g_queue_is_empty(&d->in_urbs)) {
		struct urb_rec *r = g_queue_pop_head(&d->in_urbs);
		g_free(r->data);
		g_free(r);
	}
	while (!g_queue_is_empty(&d->done)) {
		struct urb_rec *r = g_queue_pop_head(&d->done);
		g_free(r->data);
		g_free(r);
	}
	g_mutex_clear(&d->lock);
	if (d->gate_fd >= 0)
		close(d->gate_fd);
	g_free(d);
}
