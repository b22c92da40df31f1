/* SPDX-License-Identifier: ISC */
#include "replay.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { REPLAY_MAX_LINE = 4096, REPLAY_MAX_ROWS = 10000000, REPLAY_MAX_FILE = 64 << 20 };

/* Split a CSV line into fields (no quotes are needed for the numbers we
 * read; a quoted field is kept whole and its quotes dropped). */
static int split(char *line, char **f, int max)
{
	int n = 0;
	char *p = line;
	while (n < max) {
		if (*p == '"') {
			char *q = ++p, *w = p;
			while (*q && !(*q == '"' && q[1] != '"')) {
				if (*q == '"')
					q++;
				*w++ = *q++;
			}
			f[n++] = p;
			if (*q == '"')
				q++;
			*w = '\0';
			p = q;
			if (*p == ',')
				p++;
			else
				break;
			continue;
		}
		f[n++] = p;
		p += strcspn(p, ",");
		if (!*p)
			break;
		*p++ = '\0';
	}
	return n;
}

static int number(const char *s, double *out)
{
	char *end;
	errno = 0;
	*out = strtod(s, &end);
	return end != s && *end == '\0' && errno != ERANGE && isfinite(*out) ? 0 : -1;
}

int ps_replay_parse(const char *text, size_t len, const char *name, double gain,
                    double lux_per_volt, struct ps_room_daypoint **out, size_t *n, char *err,
                    size_t errlen)
{
	const char *p = text, *end = text + len;
	int lineno = 0, c_tod = -1, c_dv = -1, c_dl = -1, ncol = 0;
	size_t cap = 0;
	char line[REPLAY_MAX_LINE];
	*out = NULL;
	*n = 0;
	if (!(gain > 0)) {
		snprintf(err, errlen, "%s: the room's gain must be positive", name);
		return -1;
	}
	while (p < end) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		size_t k = nl ? (size_t)(nl - p) : (size_t)(end - p);
		char *f[64];
		int nf;
		lineno++;
		if (k >= sizeof line) {
			snprintf(err, errlen, "%s:%d: line longer than %zu bytes", name, lineno, sizeof line - 1);
			goto fail;
		}
		if (memchr(p, '\0', k)) {
			snprintf(err, errlen, "%s:%d: NUL byte", name, lineno);
			goto fail;
		}
		memcpy(line, p, k);
		line[k] = '\0';
		p += k + (nl ? 1 : 0);
		if (k && line[k - 1] == '\r')
			line[k - 1] = '\0';
		if (line[0] == '#' || line[strspn(line, " \t")] == '\0')
			continue;
		nf = split(line, f, 64);
		if (ncol == 0) {
			for (int i = 0; i < nf; i++) {
				if (strcmp(f[i], "tod_s") == 0)
					c_tod = i;
				else if (strcmp(f[i], "daylight_v") == 0)
					c_dv = i;
				else if (strcmp(f[i], "daylight_lux") == 0)
					c_dl = i;
			}
			ncol = nf;
			if (c_tod < 0 || c_dv < 0) {
				snprintf(err, errlen, "%s:%d: the header needs columns tod_s and daylight_v", name, lineno);
				goto fail;
			}
			continue;
		}
		{
			double tod, dv, dl = NAN;
			struct ps_room_daypoint *grown;
			if (nf <= c_tod || nf <= c_dv) {
				snprintf(err, errlen, "%s:%d: %d fields, the header has %d", name, lineno, nf, ncol);
				goto fail;
			}
			if (f[c_dv][0] == '\0')
				continue;   /* a fault: no daylight known */
			if (number(f[c_tod], &tod) != 0 || tod < 0 || tod > 86400) {
				snprintf(err, errlen, "%s:%d: tod_s '%s' is not seconds of a day", name, lineno, f[c_tod]);
				goto fail;
			}
			if (number(f[c_dv], &dv) != 0 || dv < 0) {
				snprintf(err, errlen, "%s:%d: daylight_v '%s' is not a voltage", name, lineno, f[c_dv]);
				goto fail;
			}
			if (c_dl >= 0 && nf > c_dl && f[c_dl][0] && (number(f[c_dl], &dl) != 0 || dl < 0)) {
				snprintf(err, errlen, "%s:%d: daylight_lux '%s' is not an illuminance", name, lineno, f[c_dl]);
				goto fail;
			}
			if (isnan(dl)) {
				if (!(lux_per_volt > 0)) {
					snprintf(err, errlen, "%s:%d: no daylight_lux and no replay_ratio to derive it", name, lineno);
					goto fail;
				}
				dl = lux_per_volt * dv;
			}
			if (*n > 0 && !(tod > (*out)[*n - 1].t)) {
				snprintf(err, errlen, "%s:%d: tod_s %g does not follow %g", name, lineno, tod, (*out)[*n - 1].t);
				goto fail;
			}
			if (*n == cap) {
				size_t ncap = cap ? cap * 2 : 1024;
				if (ncap > REPLAY_MAX_ROWS) {
					snprintf(err, errlen, "%s:%d: more than %d rows", name, lineno, REPLAY_MAX_ROWS);
					goto fail;
				}
				grown = realloc(*out, ncap * sizeof *grown);
				if (!grown) {
					snprintf(err, errlen, "%s:%d: out of memory", name, lineno);
					goto fail;
				}
				*out = grown;
				cap = ncap;
			}
			(*out)[(*n)++] = (struct ps_room_daypoint){ tod, dv / gain, dl, NAN };
		}
	}
	if (*n < 2) {
		snprintf(err, errlen, "%s: %s", name, ncol ? "fewer than two rows with daylight" : "no header line");
		goto fail;
	}
	return 0;
fail:
	free(*out);
	*out = NULL;
	*n = 0;
	errno = EINVAL;
	return -1;
}

int ps_replay_read(const char *path, double gain, double lux_per_volt,
                   struct ps_room_daypoint **out, size_t *n, char *err, size_t errlen)
{
	FILE *fp = fopen(path, "rb");
	char *buf;
	size_t len;
	int rc;
	if (!fp) {
		snprintf(err, errlen, "%s: %s", path, strerror(errno));
		return -1;
	}
	buf = malloc(REPLAY_MAX_FILE);
	len = buf ? fread(buf, 1, REPLAY_MAX_FILE, fp) : 0;
	if (!buf || ferror(fp) || len == REPLAY_MAX_FILE) {
		snprintf(err, errlen, "%s: %s", path, !buf ? "out of memory" : len == REPLAY_MAX_FILE ? "too large" : "read error");
		fclose(fp);
		free(buf);
		return -1;
	}
	fclose(fp);
	rc = ps_replay_parse(buf, len, path, gain, lux_per_volt, out, n, err, errlen);
	free(buf);
	return rc;
}
