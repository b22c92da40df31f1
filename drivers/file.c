/* SPDX-License-Identifier: ISC */
/* The file driver: each point is a small text file holding one number.  A
 * sensor or a task meter reads the number someone (a person, a script,
 * another program) wrote there; a dim or relay output writes its level
 * there.  Good for dry runs and demonstrations with no hardware and no
 * simulation: `echo 2.4 > sensor` and watch `dim`.
 *
 * It is also the skeleton to copy for a new driver (drivers/README.md): a
 * table of options, a check method for the rules across keys, open and
 * add_point reading typed values through the table, read and write
 * failing as driver.h says, and nothing else.
 *
 * Faults: a missing or unreadable file is ENODEV (a fault at once), a file
 * that does not hold a number EPROTO (a garbled reply: a fault once the
 * reading is stale), a write that fails ENODEV.  Writes go to a temporary
 * file renamed over the old one, so a reader never sees half a number. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "driver.h"
#include "file.h"

enum { FILE_MAX_POINTS = 32 };

struct file_point {
	char path[300];
	double scale;
	double full_scale;   /* a reading's full scale, 0: none */
};

struct file_dev {
	char dir[256];
	struct file_point pts[FILE_MAX_POINTS];
	int npts;
};

static const struct ps_opts_spec file_options[] = {
	{ .key = "dir", .type = PS_OPT_STRING, .scope = PS_OPT_DEVICE, .def = ".",
	  .doc = "the directory of the points' files, relative to the configuration file's" },
	{ .key = "path", .type = PS_OPT_STRING, .scope = PS_OPT_POINT,
	  .doc = "the point's file, in dir unless it starts with / (required)" },
	{ .key = "scale", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .def = "1",
	  .min = -1e9, .max = 1e9,
	  .doc = "a reading is the file's number times scale; an output writes its level over scale" },
	{ .key = "full_scale", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .def = "0",
	  .min = 0, .max = 1e15, .roles = PS_ROLE_BIT(PS_ROLE_SENSOR) | PS_ROLE_BIT(PS_ROLE_TASK_LUX),
	  .doc = "the largest reading the source can give (after scale): a reading at it is "
	         "saturation (0: none)" },
	{ .key = NULL },
};

static int file_check(const struct ps_opts *o, int role, int *line, char *why, size_t n)
{
	struct ps_opts_reader r = { o, file_options, PS_OPT_POINT, why, n, line };
	double scale = 1;
	if (role < 0)
		return 0;
	if (role == PS_ROLE_INPUT)
		return ps_opts_fail(&r, "path", "file: no input points (sensor, task, dim and relay)");
	if (!ps_opts_get(o, "path"))
		return ps_opts_fail(&r, "path", "file: 'path' (the point's file) is required");
	if (ps_opts_double(&r, "scale", &scale) != 0)
		return -1;
	if (scale == 0)
		return ps_opts_fail(&r, "scale", "scale: must not be 0");
	return 0;
}

static int file_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct ps_opts_reader r = { o, file_options, PS_OPT_DEVICE, dev->err, sizeof dev->err, NULL };
	struct file_dev *f = calloc(1, sizeof *f);
	const char *dir = NULL;
	int base;
	if (!f)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = f;
	if (ps_dev_check(dev, o, -1) != 0 || ps_opts_string(&r, "dir", &dir) != 0)
		return -1;
	/* relative to the configuration file, as psensd.conf's other paths */
	base = dir[0] != '/' && o && o->file && strrchr(o->file, '/') ? (int)(strrchr(o->file, '/') - o->file) : -1;
	if ((size_t)snprintf(f->dir, sizeof f->dir, "%.*s%s%s", base < 0 ? 0 : base, o && o->file ? o->file : "",
	                     base < 0 ? "" : "/", dir) >= sizeof f->dir)
		return ps_dev_fail(dev, EINVAL, "%s:%d: dir: longer than %zu bytes", o->file, ps_opts_line(o, "dir"),
		                   sizeof f->dir - 1);
	return 0;
}

static int file_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct ps_opts_reader r = { o, file_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	struct file_dev *f = dev->priv;
	struct file_point *p;
	const char *path = NULL;
	if (ps_dev_check(dev, o, pt->role) != 0)
		return -1;
	if (f->npts >= FILE_MAX_POINTS)
		return ps_dev_fail(dev, EINVAL, "file: at most %d points per device", FILE_MAX_POINTS);
	p = &f->pts[f->npts];
	if (ps_opts_string(&r, "path", &path) || ps_opts_double(&r, "scale", &p->scale) ||
	    ps_opts_double(&r, "full_scale", &p->full_scale))
		return -1;
	if ((size_t)snprintf(p->path, sizeof p->path, "%s%s%s", path[0] == '/' ? "" : f->dir,
	                     path[0] == '/' ? "" : "/", path) >= sizeof p->path)
		return ps_dev_fail(dev, EINVAL, "%s:%d: path: longer than %zu bytes", o->file, ps_opts_line(o, "path"),
		                   sizeof p->path - 1);
	f->npts++;
	pt->priv = p;
	return 0;
}

static int file_read(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *value)
{
	(void)mono;
	struct file_point *p = pt->priv;
	char buf[64], *end;
	ssize_t n;
	double v;
	int fd;
	(void)now;   /* a file has no time: it holds what was last written */
	if ((fd = open(p->path, O_RDONLY | O_CLOEXEC)) < 0)
		return ps_dev_fail(dev, ENODEV, "file %s: %s", p->path, strerror(errno));
	n = read(fd, buf, sizeof buf - 1);
	close(fd);
	if (n < 0)
		return ps_dev_fail(dev, ENODEV, "file %s: %s", p->path, strerror(errno));
	buf[n] = 0;
	v = strtod(buf, &end);
	while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r')
		end++;
	if (end == buf || *end || !isfinite(v))
		return ps_dev_fail(dev, EPROTO, "file %s: '%.20s' is not a number", p->path, buf);
	*value = v * p->scale;
	return 0;
}

/* The value into PATH.new, fsync'd, renamed over PATH, and PATH's
 * directory fsync'd: after a power cut the reader finds the old value or
 * the new one, never an empty file.  The same steps as sim/replace.c, here
 * again because drivers/ may use nothing of the simulation library (and no
 * library below both exists). */
static int file_put(const char *path, const char *tmp, const char *buf, size_t len)
{
	char dir[320];
	const char *slash = strrchr(path, '/');
	int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644), ok;
	if (fd < 0)
		return -1;
	ok = write(fd, buf, len) == (ssize_t)len && fsync(fd) == 0;
	if (!(close(fd) == 0 && ok) || rename(tmp, path) != 0) {
		int e = errno ? errno : EIO;
		unlink(tmp);
		errno = e;
		return -1;
	}
	snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + (slash == path) : 1, slash ? path : ".");
	if ((fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) < 0)
		return -1;
	ok = fsync(fd) == 0;
	return close(fd) == 0 && ok ? 0 : -1;
}

static int file_write(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double value)
{
	(void)mono;
	struct file_point *p = pt->priv;
	char tmp[320], buf[64];
	int len;
	(void)now;
	if (pt->role != PS_ROLE_DIM && pt->role != PS_ROLE_RELAY)
		return ps_dev_fail(dev, EINVAL, "file: %s is not an output", pt->name);
	snprintf(tmp, sizeof tmp, "%s.new", p->path);
	len = snprintf(buf, sizeof buf, "%.9g\n", value / p->scale);
	errno = 0;
	if (file_put(p->path, tmp, buf, (size_t)len) != 0)
		return ps_dev_fail(dev, ENODEV, "file %s: %s", p->path, strerror(errno ? errno : EIO));
	return 0;
}

static int file_full_scale(struct ps_dev *dev, struct ps_point *pt, double *limit)
{
	const struct file_point *p = pt->priv;
	(void)dev;
	if (!p || !(p->full_scale > 0))
		return -1;
	*limit = p->full_scale;
	return 0;
}

static void file_close(struct ps_dev *dev)
{
	free(dev->priv);
	dev->priv = NULL;
}

const struct ps_driver ps_driver_file = {
	.name = "file",
	.summary = "points in text files: read a number someone wrote, write the level (dry runs)",
	.compiled_in = 1,
	.options = file_options,
	.check = file_check,
	.open = file_open,
	.add_point = file_add_point,
	.read = file_read,
	.write = file_write,
	.close = file_close,
	.full_scale = file_full_scale,
};
