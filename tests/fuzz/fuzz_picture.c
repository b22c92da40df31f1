/* Fuzz the Radiance picture reader, and the view in its header. */
#include <stddef.h>
#include <stdint.h>

#include "picture.h"
#include "view.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_picture pic;
	struct ps_err e;
	if (ps_pic_read_mem(&pic, data, size, "fuzz.hdr", &e) == 0) {
		double v[3];
		struct ps_view view;
		ps_pic_get(&pic, pic.width - 1, pic.height - 1, v);
		ps_view_default(&view);
		if (pic.view)
			ps_view_parse(&view, pic.view, "fuzz", &e);
		ps_pic_free(&pic);
	}
	return 0;
}
