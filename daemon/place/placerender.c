/* SPDX-License-Identifier: ISC */
#include "placerender.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cache.h"
#include "render.h"

extern char **environ;

#define PATHLEN 4096

struct argv {
	char **v;
	size_t n;
	int bad;
};

static void arg(struct argv *a, const char *s)
{
	char **g = a->bad ? NULL : realloc(a->v, (a->n + 2) * sizeof *g);
	if (!g) {
		a->bad = 1;
		return;
	}
	a->v = g;
	g[a->n] = strdup(s);
	g[a->n + 1] = NULL;
	if (!g[a->n])
		a->bad = 1;
	else
		a->n++;
}

/* blank-separated words (no quoting, no expansion: never a shell) */
static void words(struct argv *a, const char *text)
{
	while (*text) {
		size_t k;
		text += strspn(text, " \t\r\n");
		k = strcspn(text, " \t\r\n");
		if (k) {
			char w[1024];
			snprintf(w, sizeof w, "%.*s", (int)(k < sizeof w ? k : sizeof w - 1), text);
			arg(a, w);
		}
		text += k;
	}
}

static void argv_free(struct argv *a)
{
	ps_render_free_argv(a->v);
	a->v = NULL;
	a->n = 0;
}

/* the command line as text, for messages */
static void argv_text(char *const *v, char *out, size_t n)
{
	size_t at = 0;
	out[0] = 0;
	for (; v && *v && at + 1 < n; v++) {
		int k = snprintf(out + at, n - at, "%s%s", at ? " " : "", *v);
		if (k < 0)
			break;
		at += (size_t)k;
	}
}

/* the view as Radiance options (the pictures' view: an angular fisheye) */
static void view_words(const struct ps_view *v, char *out, size_t n)
{
	snprintf(out, n, "-vta -vp %.15g %.15g %.15g -vd %.15g %.15g %.15g -vu %.15g %.15g %.15g -vh %.15g -vv %.15g",
	         v->vp[0], v->vp[1], v->vp[2], v->vd[0], v->vd[1], v->vd[2], v->vu[0], v->vu[1], v->vu[2], v->vh, v->vv);
}

static int spawn(char *const argv[], int in, int out, pid_t *pid)
{
	posix_spawn_file_actions_t fa;
	int rc;
	if (posix_spawn_file_actions_init(&fa) != 0)
		return errno = ENOMEM, -1;
	if (in >= 0)
		posix_spawn_file_actions_adddup2(&fa, in, 0);
	if (out >= 0)
		posix_spawn_file_actions_adddup2(&fa, out, 1);
	rc = posix_spawn(pid, argv[0], &fa, NULL, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	if (rc != 0)
		return errno = rc, -1;
	return 0;
}

static int exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0;
}

/* 1 when dir holds dc_000.hdr .. the last patch's picture */
static int set_complete(const char *dir, int npatch)
{
	char path[PATHLEN + 32];
	for (int i = 0; i < npatch; i++) {
		snprintf(path, sizeof path, "%s/dc_%03d.hdr", dir, i);
		if (!exists(path))
			return 0;
	}
	return 1;
}

/* remove a temporary set: its files, then the folder */
static void remove_set(const char *dir)
{
	DIR *d = opendir(dir);
	struct dirent *de;
	char path[PATHLEN + 300];
	if (d) {
		while ((de = readdir(d)))
			if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..")) {
				snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
				unlink(path);
			}
		closedir(d);
	}
	rmdir(dir);
}

struct tools {
	char vwrays[PATHLEN], rfluxmtx[PATHLEN], rpict[PATHLEN];
};

struct job {
	int pose;
	int elec;   /* 0: the coefficient set, 1: the electric picture */
};

struct ctx {
	struct search *s;
	const struct tools *t;
	struct job *jobs;
	int n, next, failed, serial;
	pthread_mutex_t lock;
	char err[2048];
};

/* vwrays -d: the picture's dimensions as options for rfluxmtx */
static int dimensions(const struct ctx *c, const char *view, char *out, size_t n, char *err, size_t errlen)
{
	struct argv a = { 0 };
	char size[32], why[128], cmd[PATHLEN + 600];
	int fd[2];
	pid_t pid;
	size_t got = 0;
	ssize_t k;
	snprintf(size, sizeof size, "%d", c->s->o->dc_size);
	arg(&a, c->t->vwrays);
	arg(&a, "-d");
	words(&a, view);
	arg(&a, "-x");
	arg(&a, size);
	arg(&a, "-y");
	arg(&a, size);
	if (a.bad) {
		argv_free(&a);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	argv_text(a.v, cmd, sizeof cmd);
	if (pipe2(fd, O_CLOEXEC) != 0 || (spawn(a.v, -1, fd[1], &pid) != 0 && (close(fd[0]), close(fd[1]), 1))) {
		snprintf(err, errlen, "cannot run %.1000s: %s", cmd, strerror(errno));
		argv_free(&a);
		return -1;
	}
	close(fd[1]);
	while ((k = read(fd[0], out + got, n - 1 - got)) > 0 || (k < 0 && errno == EINTR))
		if (k > 0)
			got += (size_t)k;
	close(fd[0]);
	out[got] = 0;
	if (ps_render_reap(pid, why, sizeof why) != 0) {
		snprintf(err, errlen, "%.1000s: %s", cmd, why);
		argv_free(&a);
		return -1;
	}
	argv_free(&a);
	if (!strstr(out, "-x") || !strstr(out, "-y"))
		return snprintf(err, errlen, "%.1000s: printed no -x and -y", cmd), -1;
	return 0;
}

/* vwrays -ff VIEW -x N -y N | rfluxmtx -ffc DIMS OPTIONS -o TMP/dc_%03d.hdr - RECEIVER -i OCTREE */
static int render_dc(struct ctx *c, struct pose *p, int serial, char *err, size_t errlen)
{
	const struct opts *o = c->s->o;
	struct argv vw = { 0 }, rf = { 0 };
	char view[600], dims[256], size[32], tmp[PATHLEN + 64], pattern[PATHLEN + 96], e1[1200];
	char cmd[2 * PATHLEN + 1300], why1[128] = "", why2[128] = "";
	int fd[2], rc = -1, bad1, bad2;
	pid_t p1, p2;
	view_words(&p->view, view, sizeof view);
	if (dimensions(c, view, dims, sizeof dims, e1, sizeof e1) != 0)
		return snprintf(err, errlen, "candidate %s: coefficient pictures: %.1100s", p->id, e1), -1;
	snprintf(tmp, sizeof tmp, "%s.tmp.%ld.%d", p->dcdir, (long)getpid(), serial);
	snprintf(pattern, sizeof pattern, "%s/dc_%%03d.hdr", tmp);
	snprintf(size, sizeof size, "%d", o->dc_size);
	arg(&vw, c->t->vwrays);
	arg(&vw, "-ff");
	words(&vw, view);
	arg(&vw, "-x");
	arg(&vw, size);
	arg(&vw, "-y");
	arg(&vw, size);
	arg(&rf, c->t->rfluxmtx);
	arg(&rf, "-ffc");
	words(&rf, dims);
	words(&rf, o->dc_options);
	arg(&rf, "-o");
	arg(&rf, pattern);
	arg(&rf, "-");
	arg(&rf, o->receiver);
	arg(&rf, "-i");
	arg(&rf, o->dc_octree);
	if (vw.bad || rf.bad) {
		snprintf(err, errlen, "out of memory");
		goto out;
	}
	{
		char a[PATHLEN + 600], b[PATHLEN + 600];
		argv_text(vw.v, a, sizeof a);
		argv_text(rf.v, b, sizeof b);
		snprintf(cmd, sizeof cmd, "%s | %s", a, b);
	}
	if (mkdir(tmp, 0755) != 0) {
		snprintf(err, errlen, "candidate %s: %.1000s: %s", p->id, tmp, strerror(errno));
		goto out;
	}
	if (pipe2(fd, O_CLOEXEC) != 0) {
		snprintf(err, errlen, "candidate %s: pipe: %s", p->id, strerror(errno));
		remove_set(tmp);
		goto out;
	}
	bad1 = spawn(vw.v, -1, fd[1], &p1);
	if (bad1)
		snprintf(why1, sizeof why1, "cannot run it: %s", strerror(errno));
	bad2 = spawn(rf.v, fd[0], -1, &p2);
	if (bad2)
		snprintf(why2, sizeof why2, "cannot run it: %s", strerror(errno));
	close(fd[0]);
	close(fd[1]);
	if (!bad1)
		bad1 = ps_render_reap(p1, why1, sizeof why1);
	if (!bad2)
		bad2 = ps_render_reap(p2, why2, sizeof why2);
	if (bad1 || bad2) {
		snprintf(err, errlen, "candidate %s: coefficient pictures: %s %s: %.1500s", p->id, bad2 ? "rfluxmtx" : "vwrays",
		         bad2 ? why2 : why1, cmd);
		remove_set(tmp);
		goto out;
	}
	{
		char extra[PATHLEN + 96];
		snprintf(extra, sizeof extra, "%s/dc_%03d.hdr", tmp, c->s->npatch);
		if (!set_complete(tmp, c->s->npatch) || exists(extra)) {
			snprintf(err, errlen, "candidate %s: coefficient pictures: %s did not write exactly the grid's %d "
			         "patch pictures (MF %d): %.1500s", p->id, "rfluxmtx", c->s->npatch, c->s->mf, cmd);
			remove_set(tmp);
			goto out;
		}
	}
	if (rename(tmp, p->dcdir) != 0) {
		/* another run put the same set in place meanwhile: use it */
		int e = errno;
		remove_set(tmp);
		if (!set_complete(p->dcdir, c->s->npatch)) {
			snprintf(err, errlen, "candidate %s: rename %.600s to %.600s: %s", p->id, tmp, p->dcdir, strerror(e));
			goto out;
		}
	}
	rc = 0;
out:
	argv_free(&vw);
	argv_free(&rf);
	return rc;
}

/* rpict -vta ... -x N -y N OPTIONS OCTREE > the cache's picture */
static int render_elec(struct ctx *c, struct pose *p, char *err, size_t errlen)
{
	const struct opts *o = c->s->o;
	char **v = ps_render_argv(c->t->rpict, p->view.vp, p->view.vd, p->view.vu, p->view.vh, o->elec_size,
	                          o->elec_options, o->elec_octree);
	char cmd[PATHLEN + 1200];
	struct ps_err e;
	if (!v)
		return snprintf(err, errlen, "out of memory"), -1;
	argv_text(v, cmd, sizeof cmd);
	if (ps_render_run(v, p->elecfile, &e) != 0) {
		snprintf(err, errlen, "candidate %s: electric picture: %s: %.1200s", p->id, e.msg, cmd);
		ps_render_free_argv(v);
		return -1;
	}
	ps_render_free_argv(v);
	return 0;
}

static void *worker(void *arg0)
{
	struct ctx *c = arg0;
	for (;;) {
		char err[2048];
		int j, serial, rc;
		pthread_mutex_lock(&c->lock);
		if (c->failed || c->next == c->n) {
			pthread_mutex_unlock(&c->lock);
			return NULL;
		}
		j = c->next++;
		serial = c->serial++;
		pthread_mutex_unlock(&c->lock);
		if (c->jobs[j].elec)
			rc = render_elec(c, &c->s->poses[c->jobs[j].pose], err, sizeof err);
		else
			rc = render_dc(c, &c->s->poses[c->jobs[j].pose], serial, err, sizeof err);
		if (rc != 0) {
			pthread_mutex_lock(&c->lock);
			if (!c->failed)
				snprintf(c->err, sizeof c->err, "%s", err);
			c->failed = 1;
			pthread_mutex_unlock(&c->lock);
		}
	}
}

/* 1 when a job already renders path (two candidates with the same view) */
static int queued(const struct search *s, const struct ctx *c, const char *path, int elec)
{
	for (int j = 0; j < c->n; j++)
		if (c->jobs[j].elec == elec &&
		    !strcmp(elec ? s->poses[c->jobs[j].pose].elecfile : s->poses[c->jobs[j].pose].dcdir, path))
			return 1;
	return 0;
}

static int need(const char *prog, const char *what, char *out, char *err, size_t errlen)
{
	if (ps_render_find(prog, out, PATHLEN) == 0)
		return 0;
	return snprintf(err, errlen, "%s (Radiance) is not on PATH: it renders the candidates' %s", prog, what), -1;
}

int psd_placerender_all(struct search *s, struct psd_placerender_count *n, char *err, size_t errlen)
{
	const struct opts *o = s->o;
	struct tools t;
	struct ctx c;
	struct ps_err e;
	char cache[PATHLEN], dir[PATHLEN + 16], hoct[65] = "", hrec[65] = "", hel[65] = "";
	pthread_t *th;
	int nth;
	memset(n, 0, sizeof *n);
	memset(&c, 0, sizeof c);
	if (!o->dc_octree && !o->elec_octree)
		return 0;
	if (o->dc_octree && !o->receiver)
		return snprintf(err, errlen, "-M %s: rendering the coefficient pictures needs the sky patches' receiver "
		                "file (-K)", o->dc_octree), -1;
	if ((o->dc_octree && (need("vwrays", "coefficient pictures", t.vwrays, err, errlen) != 0 ||
	                      need("rfluxmtx", "coefficient pictures", t.rfluxmtx, err, errlen) != 0)) ||
	    (o->elec_octree && need("rpict", "electric pictures", t.rpict, err, errlen) != 0))
		return -1;
	if ((o->dc_octree && (ps_cache_hash_file(o->dc_octree, hoct, &e) != 0 ||
	                      ps_cache_hash_file(o->receiver, hrec, &e) != 0)) ||
	    (o->elec_octree && ps_cache_hash_file(o->elec_octree, hel, &e) != 0))
		return snprintf(err, errlen, "%s", e.msg), -1;
	if (o->cache)
		snprintf(cache, sizeof cache, "%s", o->cache);
	else
		ps_cache_default_dir(cache, sizeof cache);
	snprintf(dir, sizeof dir, "%s/pictures", cache);
	if ((mkdir(cache, 0755) != 0 && errno != EEXIST) || (mkdir(dir, 0755) != 0 && errno != EEXIST))
		return snprintf(err, errlen, "%s: %s", dir, strerror(errno)), -1;
	c.jobs = calloc((size_t)s->nposes * 2, sizeof *c.jobs);
	if (!c.jobs)
		return snprintf(err, errlen, "out of memory"), -1;
	for (int i = 0; i < s->nposes; i++) {
		struct pose *p = &s->poses[i];
		char view[600], key[PATHLEN], hex[65];
		if (p->view.type != PS_VT_ANGULAR) {
			free(c.jobs);
			return snprintf(err, errlen, "candidate %s: rendering needs an angular fisheye view (-vta)", p->id), -1;
		}
		view_words(&p->view, view, sizeof view);
		if (o->dc_octree) {
			snprintf(key, sizeof key, "psplace rfluxmtx\noctree %s\nreceiver %s\nview %s\nsize %d\noptions %s\n"
			         "patches %d\n", hoct, hrec, view, o->dc_size, o->dc_options, s->npatch);
			ps_cache_hash_string(key, hex);
			snprintf(p->dcdir, sizeof p->dcdir, "%.3900s/dc-%s", dir, hex);
			if (set_complete(p->dcdir, s->npatch))
				n->dc_cached++;
			else if (!queued(s, &c, p->dcdir, 0))
				c.jobs[c.n++] = (struct job){ .pose = i, .elec = 0 };
		}
		if (o->elec_octree) {
			snprintf(key, sizeof key, "psplace rpict\noctree %s\nview %s\nsize %d\noptions %s\n", hel, view,
			         o->elec_size, o->elec_options);
			ps_cache_hash_string(key, hex);
			snprintf(p->elecfile, sizeof p->elecfile, "%.3900s/elec-%s.hdr", dir, hex);
			if (exists(p->elecfile))
				n->elec_cached++;
			else if (!queued(s, &c, p->elecfile, 1))
				c.jobs[c.n++] = (struct job){ .pose = i, .elec = 1 };
		}
	}
	nth = o->jobs < c.n ? o->jobs : c.n;
	if (nth < 1) {
		free(c.jobs);
		return 0;
	}
	c.s = s;
	c.t = &t;
	pthread_mutex_init(&c.lock, NULL);
	th = calloc((size_t)nth, sizeof *th);
	if (!th) {
		free(c.jobs);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	{
		int started = 0;
		for (int i = 0; i < nth; i++)
			if (pthread_create(&th[i], NULL, worker, &c) == 0)
				started++;
			else
				break;
		if (!started)
			worker(&c);
		for (int i = 0; i < started; i++)
			pthread_join(th[i], NULL);
	}
	free(th);
	pthread_mutex_destroy(&c.lock);
	for (int j = 0; j < c.next; j++)
		if (c.jobs[j].elec)
			n->elec_rendered++;
		else
			n->dc_rendered++;
	free(c.jobs);
	if (c.failed)
		return snprintf(err, errlen, "%s", c.err), -1;
	return 0;
}
