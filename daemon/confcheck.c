/* SPDX-License-Identifier: ISC */
/* What psensd -n, a start and a reload judge beyond each key alone: ranges
 * that involve two keys, and the files the configuration names (the scene,
 * the results, a loopback room's replay, the directories of the files it
 * writes), each opened and parsed as the
 * daemon would, every error with the configuration's file and line (and the
 * referenced file's own line when the parser gives one). */
#include "confcheck.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "replay.h"
#include "results.h"
#include "scene.h"

static int key_line(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = s ? ps_conf_kv(s, key) : NULL;
	return kv ? kv->line : s ? s->line : 0;
}

/* A parser's message may hold several lines (the scene reader joins every
 * error): each becomes an error of its own at the configuration's line. */
static void each_line(struct ps_conf *c, int line, const char *key, const char *msg)
{
	const char *p = msg;
	while (*p) {
		size_t n = strcspn(p, "\n");
		ps_conf_error(c, line, "%s: %.*s", key, (int)n, p);
		p += n;
		p += *p == '\n';
	}
}

static void check_ranges(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	struct ps_conf_section *s = ps_conf_section(c, "psensd");
	if (!(cf->sensor_min < cf->sensor_max))
		ps_conf_error(c, key_line(s, ps_conf_kv(s, "sensor_max") ? "sensor_max" : "sensor_min"),
		              "sensor_min %g must be below sensor_max %g: every reading would be a fault and the "
		              "lights would stay at the safe level", cf->sensor_min, cf->sensor_max);
	if (cf->sensor_saturation > 0 && !(cf->sensor_saturation > cf->sensor_min))
		ps_conf_error(c, key_line(s, "sensor_saturation"),
		              "sensor_saturation %g must be above sensor_min %g: every reading would be a fault",
		              cf->sensor_saturation, cf->sensor_min);
}

/* A file psensd writes (the database with its journal, the socket, the
 * textfile, results computed from a scene): each is made or replaced in its
 * directory, so that directory must exist and take a new file, or the
 * daemon would refuse to start with the lights at the safe level. */
static void check_output(struct ps_conf *c, int line, const char *key, const char *path)
{
	struct stat st;
	const char *slash;
	char *dir;
	if (!path)
		return;
	if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
		ps_conf_error(c, line, "%s: %s is a directory, not a file", key, path);
		return;
	}
	slash = strrchr(path, '/');
	dir = slash ? strndup(path, slash == path ? 1 : (size_t)(slash - path)) : strdup(".");
	if (!dir) {
		ps_conf_error(c, line, "%s: out of memory", key);
		return;
	}
	if (stat(dir, &st) != 0)
		ps_conf_error(c, line, "%s: %s: %s", key, dir, strerror(errno));
	else if (!S_ISDIR(st.st_mode))
		ps_conf_error(c, line, "%s: %s is not a directory", key, dir);
	else if (access(dir, W_OK | X_OK) != 0)
		ps_conf_error(c, line, "%s: %s: not writable by this user (%s)", key, dir, strerror(errno));
	free(dir);
}

void psd_confcheck_outputs(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	struct ps_conf_section *s = ps_conf_section(c, "psensd");
	check_output(c, key_line(s, "database"), "database", cf->database);
	check_output(c, key_line(s, "socket"), "socket", cf->socket_path);
	check_output(c, key_line(ps_conf_section(c, "prometheus"), "textfile"), "textfile", cf->prom.textfile);
}

/* A scene and its results, named at lines ls and lr of the file. */
static void check_pair(struct ps_conf *c, const char *scene, const char *results, int ls, int lr)
{
	struct stat ss, rs;
	struct ps_err e;
	int have_scene = 0, stale;
	if (scene) {
		struct ps_scene sc;
		if (stat(scene, &ss) != 0) {
			ps_conf_error(c, ls, "scene: %s: %s", scene, strerror(errno));
		} else {
			memset(&sc, 0, sizeof sc);
			if (ps_scene_read(&sc, scene, &e) != 0)
				each_line(c, ls, "scene", e.msg);
			else
				have_scene = 1;
			ps_scene_free(&sc);
		}
	}
	if (!results)
		return;
	if (stat(results, &rs) != 0) {
		if (!have_scene && !scene)
			ps_conf_error(c, lr, "results: %s: %s (and no scene = to compute them from)", results,
			              strerror(errno));
		else
			check_output(c, lr, "results", results);
		return;   /* psensd runs psscene on the scene at start */
	}
	/* results older than the scene are recomputed at start: judged then */
	stale = have_scene && rs.st_mtime < ss.st_mtime;
	if (!stale) {
		struct ps_results r;
		memset(&r, 0, sizeof r);
		if (ps_results_read(&r, results, &e) != 0)
			each_line(c, lr, "results", e.msg);
		ps_results_free(&r);
	}
}

static void check_scene_results(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	struct ps_conf_section *s = ps_conf_section(c, "psensd");
	check_pair(c, cf->scene, cf->results, key_line(s, "scene"), key_line(s, "results"));
	for (size_t i = 0; i < cf->nzone; i++) {
		const struct psd_zone_conf *zc = &cf->zone[i];
		char sec[64];
		struct ps_conf_section *zs;
		if (!zc->scene && !zc->results)
			continue;
		snprintf(sec, sizeof sec, "zone %s", zc->name);
		zs = ps_conf_section(c, sec);
		check_pair(c, zc->scene, zc->results, key_line(zs, "scene"), key_line(zs, "results"));
	}
}

/* A device's replay: resolved against the configuration's directory (the
 * driver gets the resolved name), read and parsed. */
static void check_replays(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	for (size_t i = 0; i < cf->ndev; i++) {
		struct ps_opts *o = &cf->dev[i].opts;
		const char *ratio_s = NULL;
		struct ps_opt *rp = NULL;
		for (size_t k = 0; k < o->n; k++) {
			if (strcmp(o->v[k].key, "replay") == 0)
				rp = &o->v[k];
			else if (strcmp(o->v[k].key, "replay_ratio") == 0)
				ratio_s = o->v[k].value;
		}
		if (!rp || cf->npath >= PSD_MAX_DEVICES)
			continue;
		{
			char *path = ps_conf_path_join(c->dir, rp->value), err[512];
			struct ps_room_daypoint *dp = NULL;
			size_t n = 0;
			double ratio = ratio_s ? strtod(ratio_s, NULL) : 0;
			if (!path) {
				ps_conf_error(c, rp->line, "replay: out of memory");
				continue;
			}
			cf->path[cf->npath++] = path;
			rp->value = path;
			if (ps_replay_read(path, 1.0, ratio, &dp, &n, err, sizeof err) != 0)
				ps_conf_error(c, rp->line, "replay: %s", err);
			free(dp);
		}
	}
}

void psd_confcheck_ranges(struct psd_config *cf)
{
	check_ranges(cf);
}

void psd_confcheck_files(struct psd_config *cf)
{
	check_scene_results(cf);
	check_replays(cf);
}
