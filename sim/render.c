/* SPDX-License-Identifier: ISC */
#include "render.h"
#include "replace.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

double ps_render_field(double extent_rad)
{
	double deg = extent_rad * 180.0 / M_PI;
	if (deg > 90.0 + 1e-9)
		return 360.0;
	if (deg >= 90.0 - 1e-9)
		return 180.0;
	/* an angular fisheye's edge midpoint sits at vh / 2 degrees */
	return fmin(180.0, ceil(2.0 * deg));
}

int ps_render_find(const char *prog, char *out, size_t len)
{
	const char *path = getenv("PATH");
	if (strchr(prog, '/')) {
		snprintf(out, len, "%s", prog);
		return access(out, X_OK) == 0 ? 0 : -1;
	}
	if (!path)
		path = "/usr/bin:/bin";
	while (*path) {
		size_t n = strcspn(path, ":");
		snprintf(out, len, "%.*s/%s", (int)n, n ? path : ".", prog);
		if (access(out, X_OK) == 0)
			return 0;
		path += n + (path[n] == ':');
	}
	return -1;
}

static int push(char ***v, size_t *n, const char *s)
{
	char **g = realloc(*v, (*n + 2) * sizeof *g);
	if (!g)
		return -1;
	*v = g;
	g[*n] = strdup(s);
	g[*n + 1] = NULL;
	return g[(*n)++] ? 0 : -1;
}

char **ps_render_argv(const char *rpict, const double pos[3], const double dir[3],
                      const double up[3], double field, int resolution, const char *options,
                      const char *octree)
{
	char **v = NULL, buf[128];
	size_t n = 0;
	int bad = 0;
	bad |= push(&v, &n, rpict);
	bad |= push(&v, &n, "-vta");
	bad |= push(&v, &n, "-vp");
	for (int i = 0; i < 3; i++) {
		snprintf(buf, sizeof buf, "%.17g", pos[i]);
		bad |= push(&v, &n, buf);
	}
	bad |= push(&v, &n, "-vd");
	for (int i = 0; i < 3; i++) {
		snprintf(buf, sizeof buf, "%.17g", dir[i]);
		bad |= push(&v, &n, buf);
	}
	bad |= push(&v, &n, "-vu");
	for (int i = 0; i < 3; i++) {
		snprintf(buf, sizeof buf, "%.17g", up[i]);
		bad |= push(&v, &n, buf);
	}
	snprintf(buf, sizeof buf, "%g", field);
	bad |= push(&v, &n, "-vh");
	bad |= push(&v, &n, buf);
	bad |= push(&v, &n, "-vv");
	bad |= push(&v, &n, buf);
	snprintf(buf, sizeof buf, "%d", resolution);
	bad |= push(&v, &n, "-x");
	bad |= push(&v, &n, buf);
	bad |= push(&v, &n, "-y");
	bad |= push(&v, &n, buf);
	if (options) {
		/* words separated by blanks; no shell quoting, no expansion */
		const char *p = options;
		while (*p) {
			size_t k;
			p += strspn(p, " \t");
			k = strcspn(p, " \t");
			if (k) {
				char *w = strndup(p, k);
				bad |= !w || push(&v, &n, w);
				free(w);
			}
			p += k;
		}
	}
	bad |= push(&v, &n, octree);
	if (bad) {
		ps_render_free_argv(v);
		return NULL;
	}
	return v;
}

void ps_render_free_argv(char **argv)
{
	if (!argv)
		return;
	for (char **p = argv; *p; p++)
		free(*p);
	free(argv);
}

int ps_render_reap(pid_t pid, char *why, size_t len)
{
	int status;
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return snprintf(why, len, "could not be waited for: %s", strerror(errno)), -1;
	if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
		return 0;
	if (WIFSIGNALED(status))
		snprintf(why, len, "was killed by signal %d", WTERMSIG(status));
	else
		snprintf(why, len, "exited with status %d", WEXITSTATUS(status));
	return -1;
}

int ps_render_run(char *const argv[], const char *out_path, struct ps_err *e)
{
	char tmp[4200], why[128];
	posix_spawn_file_actions_t fa;
	pid_t pid;
	int rc;
	snprintf(tmp, sizeof tmp, "%s.rendering.%ld", out_path, (long)getpid());
	if (posix_spawn_file_actions_init(&fa) != 0)
		return ps_err_sys(e, "posix_spawn_file_actions_init");
	posix_spawn_file_actions_addopen(&fa, 1, tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	if (rc != 0) {
		errno = rc;
		unlink(tmp);
		return ps_err_sys(e, "cannot run %s", argv[0]);
	}
	if (ps_render_reap(pid, why, sizeof why) != 0) {
		unlink(tmp);
		return ps_err_set(e, PS_EIO, "%s %s", argv[0], why);
	}
	return ps_replace_install(tmp, out_path, e);
}
