/* SPDX-License-Identifier: ISC */
/* Fuzz the Radiance picture reader, and the view in its header; and the
 * row-by-row reader (header alone, scanline starts, rows decoded or only
 * checked), which must accept exactly what the whole reader accepts. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "picture.h"
#include "view.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int row(void *ctx, int y, const uint8_t *px)
{
	(void)ctx;
	(void)y;
	return px[0] == 255 && px[1] == 254 ? 0 : 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_picture pic, head;
	struct ps_err e;
	size_t off;
	int whole = ps_picture_read_mem(&pic, data, size, "fuzz.hdr", &e);
	if (ps_picture_head_mem(&head, data, size, "fuzz.hdr", &off, &e) == 0) {
		if (ps_picture_is_standard(&head)) {
			size_t *starts = malloc((size_t)head.height * sizeof *starts);
			uint8_t *want = malloc((size_t)head.height);
			int a, b;
			if (starts && want) {
				for (int y = 0; y < head.height; y++)
					want[y] = (uint8_t)(y & 1);
				a = ps_picture_scanline_starts(&head, data, size, "fuzz.hdr", off, starts, &e);
				b = ps_picture_scan_rows(&head, data, size, "fuzz.hdr", off, 0, head.height, want,
				                         row, NULL, &e);
				if ((a == 0) != (whole == 0) || (b == 0) != (whole == 0))
					abort();   /* the two readers disagree */
			}
			free(starts);
			free(want);
		}
		ps_picture_free(&head);
	}
	if (whole == 0) {
		double v[3];
		struct ps_view view;
		ps_picture_get(&pic, pic.width - 1, pic.height - 1, v);
		ps_view_default(&view);
		if (pic.view)
			ps_view_parse(&view, pic.view, "fuzz", &e);
		ps_picture_free(&pic);
	}
	return 0;
}
