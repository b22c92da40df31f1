/* SPDX-License-Identifier: ISC */
#include <errno.h>
#include <spawn.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "refresh.h"
#include "config.h"
#include "log.h"

extern char **environ;

/* Recompute one results file with psscene when it is missing or older than
 * its scene file. */
static int refresh_one(const char *scene, const char *results, const char *self)
{
	struct stat rs, ss;
	char psscene[4096];
	const char *slash = strrchr(self, '/');
	char *argv[6];
	pid_t pid;
	int status;
	if (!scene || !results)
		return 0;
	if (stat(scene, &ss) != 0) {
		psd_log_err("%s", scene);
		return -1;
	}
	if (stat(results, &rs) == 0 && rs.st_mtime >= ss.st_mtime)
		return 0;
	/* psscene beside this psensd, else on PATH */
	if (slash)
		snprintf(psscene, sizeof psscene, "%.*s/psscene", (int)(slash - self), self);
	if (!slash || access(psscene, X_OK) != 0)
		snprintf(psscene, sizeof psscene, "psscene");
	psd_log_info("results %s missing or older than %s: running %s", results, scene, psscene);
	argv[0] = psscene;
	argv[1] = "-q";
	argv[2] = "-o";
	argv[3] = (char *)results;
	argv[4] = (char *)scene;
	argv[5] = NULL;
	if ((errno = posix_spawnp(&pid, psscene, NULL, NULL, argv, environ)) != 0) {
		psd_log_err("cannot run %s", psscene);
		return -1;
	}
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return -1;
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		psd_log_errx("%s failed on %s", psscene, scene);
		return -1;
	}
	return 0;
}

/* [psensd]'s results and each zone's own, each distinct file once (zones
 * sharing a scene share its results: psscene runs once for it). */
int psd_refresh_results(const struct psd_config *cf, const char *self)
{
	if (refresh_one(cf->scene, cf->results, self) != 0)
		return -1;
	for (size_t i = 0; i < cf->nzone; i++) {
		const char *r = psd_config_zone_results(cf, &cf->zone[i]);
		/* none to make (no results), or made already for [psensd] or a zone before */
		int seen = !r || (cf->results && strcmp(r, cf->results) == 0);
		for (size_t k = 0; k < i && !seen; k++) {
			const char *rk = psd_config_zone_results(cf, &cf->zone[k]);
			seen = rk && strcmp(r, rk) == 0;
		}
		if (!seen && refresh_one(psd_config_zone_scene(cf, &cf->zone[i]), r, self) != 0)
			return -1;
	}
	return 0;
}

