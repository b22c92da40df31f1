/* SPDX-License-Identifier: ISC */
#include <errno.h>
#include <spawn.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "daemon.h"
#include "log.h"

extern char **environ;

/* Recompute the results with psscene when they are missing or older than
 * the scene file. */
int psd_refresh_results(const struct psd_config *cf, const char *self)
{
	struct stat rs, ss;
	char psscene[4096];
	const char *slash = strrchr(self, '/');
	char *argv[6];
	pid_t pid;
	int status;
	if (!cf->scene)
		return 0;
	if (stat(cf->scene, &ss) != 0) {
		log_err("%s", cf->scene);
		return -1;
	}
	if (stat(cf->results, &rs) == 0 && rs.st_mtime >= ss.st_mtime)
		return 0;
	/* psscene beside this psensd, else on PATH */
	if (slash)
		snprintf(psscene, sizeof psscene, "%.*s/psscene", (int)(slash - self), self);
	if (!slash || access(psscene, X_OK) != 0)
		snprintf(psscene, sizeof psscene, "psscene");
	log_info("results %s missing or older than %s: running %s", cf->results, cf->scene, psscene);
	argv[0] = psscene;
	argv[1] = "-q";
	argv[2] = "-o";
	argv[3] = cf->results;
	argv[4] = cf->scene;
	argv[5] = NULL;
	if ((errno = posix_spawnp(&pid, psscene, NULL, NULL, argv, environ)) != 0) {
		log_err("cannot run %s", psscene);
		return -1;
	}
	while (waitpid(pid, &status, 0) < 0)
		if (errno != EINTR)
			return -1;
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		log_errx("%s failed on %s", psscene, cf->scene);
		return -1;
	}
	return 0;
}

