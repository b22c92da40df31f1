/* SPDX-License-Identifier: ISC */
/* The emulated GPIO chip (see vgpio.h).  How it fits umockdev: the chip
 * node and a pool of extra nodes are emulated; a line request answers with a
 * new descriptor the handler opens on a pool node *through the preload*, so
 * the descriptor is emulated too (plain files for line handles, FIFOs for
 * event lines, whose data the handler writes as struct gpioevent_data).
 * umockdev runs the handler in its own thread of this process, which is why
 * the program under test must host the emulator (tests/emu/vgpio_fixture.c). */
#include "vgpio.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include <linux/gpio.h>
#include <umockdev.h>

enum { SLOTS = 16, MAXLINES = 64, KFIFO = 16 };

struct slot {
	int used, event;
	unsigned n, off[GPIOHANDLES_MAX];
	uint32_t hflags, eflags;
	int wfd;                  /* our end of an event FIFO (by its real path) */
	char node[96];
};

struct vgpio {
	UMockdevTestbed *tb;
	UMockdevIoctlBase *h;
	GMutex lock;
	char name[32], node[64];
	unsigned nlines;
	int level[MAXLINES];
	int owner[MAXLINES];      /* slot index + 1 (events after SLOTS), 0 free */
	unsigned long dropped[MAXLINES];
	double rate[MAXLINES];
	int s2[MAXLINES], s3[MAXLINES];   /* divider pins of a TSL230R line, -1: none */
	uint64_t next_edge[MAXLINES];
	struct slot hs[SLOTS], es[SLOTS];
	GThread *gen;
	int stop;
};

static uint64_t mono_ns(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static struct slot *slot_at(struct vgpio *v, int idx)
{
	return idx < SLOTS ? &v->hs[idx] : &v->es[idx - SLOTS];
}

static int slot_of(struct vgpio *v, const char *node)
{
	for (int i = 0; i < SLOTS; i++) {
		if (strcmp(v->hs[i].node, node) == 0)
			return i;
		if (strcmp(v->es[i].node, node) == 0)
			return SLOTS + i;
	}
	return -1;
}

/* the kernel's 16-event kfifo: a full buffer drops the event */
static void push(struct vgpio *v, unsigned line, struct slot *s, uint64_t ts, uint32_t id)
{
	struct gpioevent_data ev = { .timestamp = ts, .id = id };
	int pending = 0;
	if (ioctl(s->wfd, FIONREAD, &pending) == 0 && pending >= KFIFO * (int)sizeof ev) {
		v->dropped[line]++;
		return;
	}
	if (write(s->wfd, &ev, sizeof ev) != (ssize_t)sizeof ev)
		v->dropped[line]++;
}

/* caller holds the lock */
static void edge(struct vgpio *v, unsigned line, int lvl, uint64_t ts)
{
	struct slot *s;
	int logical;
	if (v->level[line] == lvl)
		return;
	v->level[line] = lvl;
	if (!v->owner[line] || !(s = slot_at(v, v->owner[line] - 1))->event)
		return;
	logical = lvl ^ !!(s->hflags & GPIOHANDLE_REQUEST_ACTIVE_LOW);
	if (logical && (s->eflags & GPIOEVENT_REQUEST_RISING_EDGE))
		push(v, line, s, ts, GPIOEVENT_EVENT_RISING_EDGE);
	if (!logical && (s->eflags & GPIOEVENT_REQUEST_FALLING_EDGE))
		push(v, line, s, ts, GPIOEVENT_EVENT_FALLING_EDGE);
}

void vgpio_set(struct vgpio *v, unsigned line, int level)
{
	g_mutex_lock(&v->lock);
	if (line < v->nlines)
		edge(v, line, !!level, mono_ns());
	g_mutex_unlock(&v->lock);
}

void vgpio_press(struct vgpio *v, unsigned line, int pressed, int bounces, int hold_ms)
{
	struct timespec bounce = { 0, 1000000 }, hold = { hold_ms / 1000, (long)(hold_ms % 1000) * 1000000L };
	for (int i = 0; i < bounces; i++) {
		vgpio_set(v, line, pressed);
		nanosleep(&bounce, NULL);
		vgpio_set(v, line, !pressed);
		nanosleep(&bounce, NULL);
	}
	vgpio_set(v, line, pressed);
	nanosleep(&hold, NULL);
	vgpio_set(v, line, !pressed);
}

/* The pulse generator: every 200 us, the edges whose time has come, each
 * with its own timestamp (rising at t, falling half a period later). */
static gpointer generator(gpointer data)
{
	struct vgpio *v = data;
	struct timespec tick = { 0, 200000 };
	while (!__atomic_load_n(&v->stop, __ATOMIC_ACQUIRE)) {
		uint64_t now = mono_ns();
		g_mutex_lock(&v->lock);
		for (unsigned l = 0; l < v->nlines; l++) {
			static const double div[4] = { 1, 2, 10, 100 };
			uint64_t period, behind;
			double hz = v->rate[l];
			if (hz <= 0)
				continue;
			if (v->s2[l] >= 0)   /* S2 S3: 00 /1, 01 /2, 10 /10, 11 /100 */
				hz /= div[2 * v->level[v->s2[l]] + v->level[v->s3[l]]];
			period = (uint64_t)(1e9 / hz);
			if (period == 0)
				period = 1;
			/* Far behind (a rate beyond what a 200 us tick can walk edge
			 * by edge): the kernel's buffer holds 16 events, so all but
			 * the last few due edges would be dropped anyway; count them
			 * dropped in one step instead of walking millions of edges
			 * under the lock, which starved the process under test. */
			behind = v->next_edge[l] <= now ? (now - v->next_edge[l]) / period : 0;
			if (behind > 4 * KFIFO) {
				uint64_t skip = behind - 4 * KFIFO;
				if (v->owner[l] && slot_at(v, v->owner[l] - 1)->event)
					v->dropped[l] += 2 * skip;
				v->next_edge[l] += skip * period;
			}
			while (v->next_edge[l] <= now) {
				edge(v, l, 1, v->next_edge[l]);
				edge(v, l, 0, v->next_edge[l] + period / 2);
				v->next_edge[l] += period;
			}
		}
		g_mutex_unlock(&v->lock);
		nanosleep(&tick, NULL);
	}
	return NULL;
}

void vgpio_rate(struct vgpio *v, unsigned line, double hz)
{
	g_mutex_lock(&v->lock);
	if (line < v->nlines) {
		v->rate[line] = hz;
		v->next_edge[line] = mono_ns();
	}
	g_mutex_unlock(&v->lock);
}

void vgpio_tsl230(struct vgpio *v, unsigned line, double hz, unsigned s2, unsigned s3)
{
	g_mutex_lock(&v->lock);
	if (line < v->nlines && s2 < v->nlines && s3 < v->nlines) {
		v->s2[line] = (int)s2;
		v->s3[line] = (int)s3;
		v->rate[line] = hz;
		v->next_edge[line] = mono_ns();
	}
	g_mutex_unlock(&v->lock);
}

int vgpio_level(struct vgpio *v, unsigned line)
{
	int l;
	g_mutex_lock(&v->lock);
	l = line < v->nlines ? v->level[line] : -1;
	g_mutex_unlock(&v->lock);
	return l;
}

int vgpio_held(struct vgpio *v, unsigned line)
{
	int h;
	g_mutex_lock(&v->lock);
	h = line < v->nlines && v->owner[line];
	g_mutex_unlock(&v->lock);
	return h;
}

unsigned long vgpio_dropped(struct vgpio *v, unsigned line)
{
	unsigned long d;
	g_mutex_lock(&v->lock);
	d = line < v->nlines ? v->dropped[line] : 0;
	g_mutex_unlock(&v->lock);
	return d;
}

void vgpio_dump(struct vgpio *v, char *buf, unsigned len)
{
	unsigned k = 0;
	g_mutex_lock(&v->lock);
	buf[0] = 0;
	for (unsigned l = 0; l < v->nlines && k < len; l++) {
		int w = snprintf(buf + k, len - k, "line %u level %d held %d dropped %lu\n", l, v->level[l],
		                 !!v->owner[l], v->dropped[l]);
		if (w > 0)
			k += (unsigned)w;
	}
	g_mutex_unlock(&v->lock);
}

/* A line descriptor was closed: umockdev finalises the client object (it
 * emits no signal for it in 0.17), and the lines are free again. */
struct gone {
	struct vgpio *v;
	char node[96];
};

static void client_gone(gpointer data, GObject *obj)
{
	struct gone *g = data;
	struct vgpio *v = g->v;
	int idx;
	(void)obj;
	g_mutex_lock(&v->lock);
	if ((idx = slot_of(v, g->node)) >= 0 && slot_at(v, idx)->used) {
		struct slot *s = slot_at(v, idx);
		for (unsigned i = 0; i < s->n; i++)
			if (v->owner[s->off[i]] == idx + 1)
				v->owner[s->off[i]] = 0;
		s->used = 0;
	}
	g_mutex_unlock(&v->lock);
	g_free(g);
}

static void client_connected(UMockdevIoctlBase *h, UMockdevIoctlClient *c, gpointer user)
{
	struct gone *g = g_new0(struct gone, 1);
	(void)h;
	g->v = user;
	g_strlcpy(g->node, umockdev_ioctl_client_get_devnode(c), sizeof g->node);
	g_object_weak_ref(G_OBJECT(c), client_gone, g);
}

static int claim(struct vgpio *v, struct slot *pool, int base, const uint32_t *offs, unsigned n, int *out)
{
	if (n == 0 || n > GPIOHANDLES_MAX)
		return EINVAL;
	for (unsigned i = 0; i < n; i++) {
		if (offs[i] >= v->nlines)
			return EINVAL;
		if (v->owner[offs[i]])
			return EBUSY;
	}
	for (int i = 0; i < SLOTS; i++)
		if (!pool[i].used) {
			pool[i].used = 1;
			pool[i].n = n;
			for (unsigned k = 0; k < n; k++) {
				pool[i].off[k] = offs[k];
				v->owner[offs[k]] = base + i + 1;
			}
			*out = i;
			return 0;
		}
	return EMFILE;
}

static void *arg_of(UMockdevIoctlClient *c, size_t len, UMockdevIoctlData **d)
{
	GError *err = NULL;
	*d = umockdev_ioctl_data_resolve(umockdev_ioctl_client_get_arg(c), 0, len, &err);
	if (!*d) {
		g_clear_error(&err);
		return NULL;
	}
	return (*d)->data;
}

static gboolean on_ioctl(UMockdevIoctlBase *h, UMockdevIoctlClient *c, gpointer user)
{
	struct vgpio *v = user;
	gulong req = umockdev_ioctl_client_get_request(c);
	const char *node = umockdev_ioctl_client_get_devnode(c);
	UMockdevIoctlData *d = NULL;
	long ret = 0;
	int eno = 0, idx;
	(void)h;
	g_mutex_lock(&v->lock);
	if (strcmp(node, v->node) == 0) {
		if (req == GPIO_GET_CHIPINFO_IOCTL) {
			struct gpiochip_info *ci = arg_of(c, sizeof *ci, &d);
			if (ci) {
				memset(ci, 0, sizeof *ci);
				g_strlcpy(ci->name, v->name, sizeof ci->name);
				g_strlcpy(ci->label, "psensd-vgpio", sizeof ci->label);
				ci->lines = v->nlines;
			}
		} else if (req == GPIO_GET_LINEINFO_IOCTL) {
			struct gpioline_info *li = arg_of(c, sizeof *li, &d);
			if (!li || li->line_offset >= v->nlines) {
				ret = -1;
				eno = EINVAL;
			} else {
				unsigned o = li->line_offset;
				memset(li, 0, sizeof *li);
				li->line_offset = o;
				snprintf(li->name, sizeof li->name, "LINE%u", o);
				if (v->owner[o]) {
					struct slot *s = slot_at(v, v->owner[o] - 1);
					li->flags = GPIOLINE_FLAG_KERNEL |
					            (s->hflags & GPIOHANDLE_REQUEST_OUTPUT ? GPIOLINE_FLAG_IS_OUT : 0) |
					            (s->hflags & GPIOHANDLE_REQUEST_ACTIVE_LOW ? GPIOLINE_FLAG_ACTIVE_LOW : 0);
					g_strlcpy(li->consumer, "held", sizeof li->consumer);
				}
			}
		} else if (req == GPIO_GET_LINEHANDLE_IOCTL) {
			struct gpiohandle_request *r = arg_of(c, sizeof *r, &d);
			int e = r ? claim(v, v->hs, 0, r->lineoffsets, r->lines, &idx) : EFAULT;
			if (e) {
				ret = -1;
				eno = e;
			} else {
				struct slot *s = &v->hs[idx];
				s->hflags = r->flags;
				if (r->flags & GPIOHANDLE_REQUEST_OUTPUT)
					for (unsigned i = 0; i < r->lines; i++)
						v->level[r->lineoffsets[i]] =
						        !!r->default_values[i] ^ !!(r->flags & GPIOHANDLE_REQUEST_ACTIVE_LOW);
				if ((r->fd = open(s->node, O_RDWR | O_CLOEXEC)) < 0) {
					ret = -1;
					eno = errno;
					s->used = 0;
				}
			}
		} else if (req == GPIO_GET_LINEEVENT_IOCTL) {
			struct gpioevent_request *r = arg_of(c, sizeof *r, &d);
			int e = r ? claim(v, v->es, SLOTS, &r->lineoffset, 1, &idx) : EFAULT;
			if (e) {
				ret = -1;
				eno = e;
			} else {
				struct slot *s = &v->es[idx];
				char junk[512];
				s->hflags = r->handleflags | GPIOHANDLE_REQUEST_INPUT;
				s->eflags = r->eventflags;
				while (read(s->wfd, junk, sizeof junk) > 0)
					;   /* a new request starts with an empty buffer */
				if ((r->fd = open(s->node, O_RDWR | O_CLOEXEC)) < 0) {
					ret = -1;
					eno = errno;
					s->used = 0;
				}
			}
		} else {
			ret = -1;
			eno = ENOTTY;
		}
	} else if ((idx = slot_of(v, node)) >= 0) {
		struct slot *s = slot_at(v, idx);
		int al = !!(s->hflags & GPIOHANDLE_REQUEST_ACTIVE_LOW);
		struct gpiohandle_data *hd;
		if (req == GPIOHANDLE_GET_LINE_VALUES_IOCTL && (hd = arg_of(c, sizeof *hd, &d))) {
			memset(hd, 0, sizeof *hd);
			for (unsigned i = 0; i < s->n; i++)
				hd->values[i] = (uint8_t)(v->level[s->off[i]] ^ al);
		} else if (req == GPIOHANDLE_SET_LINE_VALUES_IOCTL && (hd = arg_of(c, sizeof *hd, &d))) {
			if (s->event || !(s->hflags & GPIOHANDLE_REQUEST_OUTPUT)) {
				ret = -1;
				eno = EPERM;
			} else {
				for (unsigned i = 0; i < s->n; i++)
					v->level[s->off[i]] = !!hd->values[i] ^ al;
			}
		} else {
			ret = -1;
			eno = ENOTTY;
		}
	} else {
		ret = -1;
		eno = ENOTTY;
	}
	g_mutex_unlock(&v->lock);
	if (d)
		g_object_unref(d);
	umockdev_ioctl_client_complete(c, ret, eno);
	return TRUE;
}

struct vgpio *vgpio_new(const char *name, unsigned nlines)
{
	struct vgpio *v = g_new0(struct vgpio, 1);
	GError *err = NULL;
	char *desc, *root;
	g_mutex_init(&v->lock);
	g_strlcpy(v->name, name, sizeof v->name);
	snprintf(v->node, sizeof v->node, "/dev/%s", name);
	v->nlines = nlines > MAXLINES ? MAXLINES : nlines;
	for (int i = 0; i < MAXLINES; i++)
		v->s2[i] = v->s3[i] = -1;
	v->tb = umockdev_testbed_new();
	/* "=00": a plain-file node; the dev attribute is what libgpiod compares
	 * with the node's st_rdev */
	desc = g_strdup_printf("P: /devices/platform/vgpio/%s\nN: %s=00\nE: SUBSYSTEM=gpio\nE: DEVNAME=/dev/%s\n"
	                       "E: MAJOR=254\nE: MINOR=0\nA: dev=254:0\\n\n", name, name, name);
	if (!umockdev_testbed_add_from_string(v->tb, desc, &err))
		goto bad;
	g_free(desc);
	desc = NULL;
	v->h = umockdev_ioctl_base_new();
	g_signal_connect(v->h, "handle-ioctl", G_CALLBACK(on_ioctl), v);
	g_signal_connect(v->h, "client-connected", G_CALLBACK(client_connected), v);
	if (!umockdev_testbed_attach_ioctl(v->tb, v->node, v->h, &err))
		goto bad;
	root = umockdev_testbed_get_root_dir(v->tb);
	{
		char *dir = g_strdup_printf("%s/dev/vgpio-%s", root, name);
		g_mkdir_with_parents(dir, 0755);
		g_free(dir);
	}
	for (int i = 0; i < SLOTS; i++)
		for (int ev = 0; ev < 2; ev++) {
			struct slot *s = ev ? &v->es[i] : &v->hs[i];
			char *real;
			s->event = ev;
			s->wfd = -1;
			snprintf(s->node, sizeof s->node, "/dev/vgpio-%s/%c%d", name, ev ? 'e' : 'h', i);
			real = g_strconcat(root, s->node, NULL);
			if (ev) {
				mkfifo(real, 0600);
				s->wfd = open(real, O_RDWR | O_NONBLOCK | O_CLOEXEC);
			} else {
				g_file_set_contents(real, "", 0, NULL);
			}
			g_free(real);
			if (!umockdev_testbed_attach_ioctl(v->tb, s->node, v->h, &err)) {
				g_free(root);
				goto bad;
			}
		}
	g_free(root);
	v->gen = g_thread_new("vgpio-pulses", generator, v);
	return v;
bad:
	fprintf(stderr, "vgpio: %s\n", err ? err->message : "setup failed");
	g_clear_error(&err);
	g_free(desc);
	return NULL;
}

void vgpio_free(struct vgpio *v)
{
	GError *err = NULL;
	if (!v)
		return;
	__atomic_store_n(&v->stop, 1, __ATOMIC_RELEASE);
	if (v->gen)
		g_thread_join(v->gen);
	for (int i = 0; i < SLOTS; i++) {
		umockdev_testbed_detach_ioctl(v->tb, v->hs[i].node, &err);
		g_clear_error(&err);
		umockdev_testbed_detach_ioctl(v->tb, v->es[i].node, &err);
		g_clear_error(&err);
		if (v->es[i].wfd >= 0)
			close(v->es[i].wfd);
	}
	umockdev_testbed_detach_ioctl(v->tb, v->node, &err);
	g_clear_error(&err);
	g_object_unref(v->h);
	g_object_unref(v->tb);
	g_mutex_clear(&v->lock);
	g_free(v);
}
