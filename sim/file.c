#include "file.h"

#include <stdio.h>
#include <stdlib.h>

int ps_read_file(const char *path, size_t max, uint8_t **data, size_t *len, struct ps_err *e)
{
	FILE *fp = fopen(path, "rb");
	uint8_t *buf = NULL;
	size_t n = 0, cap = 0;
	*data = NULL;
	*len = 0;
	if (!fp)
		return ps_errsys(e, "%s", path);
	for (;;) {
		size_t got;
		if (n + 1 >= cap) {
			size_t ncap = cap ? cap * 2 : 65536;
			uint8_t *nb;
			if (cap > max) {
				fclose(fp);
				free(buf);
				return ps_errf(e, PS_ERANGE, "%s: larger than %zu bytes", path, max);
			}
			nb = realloc(buf, ncap);
			if (!nb) {
				fclose(fp);
				free(buf);
				return ps_errf(e, PS_ENOMEM, "%s: out of memory", path);
			}
			buf = nb;
			cap = ncap;
		}
		got = fread(buf + n, 1, cap - n - 1, fp);
		n += got;
		if (got == 0)
			break;
	}
	if (ferror(fp)) {
		int rc = ps_errsys(e, "%s: read error", path);
		fclose(fp);
		free(buf);
		return rc;
	}
	fclose(fp);
	if (n > max) {
		free(buf);
		return ps_errf(e, PS_ERANGE, "%s: larger than %zu bytes", path, max);
	}
	buf[n] = '\0';
	*data = buf;
	*len = n;
	return 0;
}
