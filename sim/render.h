/* SPDX-License-Identifier: ISC */
/* Rendering missing pictures with Radiance's rpict, for users who have it:
 * the smallest view that holds the sensitivity, run with an argument vector
 * (never a shell), its output written to the picture file. */
#ifndef PS_RENDER_H
#define PS_RENDER_H

#include <stddef.h>
#include <sys/types.h>

#include "err.h"

/* The -vh (= -vv) of an angular fisheye that holds every direction the
 * sensor sees: 180 for a hemispherical sensor, 360 only when the
 * sensitivity passes 90 degrees, narrower for a narrow sensor. */
double ps_render_field(double extent_rad);

/* Find a program on PATH (or use it as given when it has a '/'); 0 found. */
int ps_render_find(const char *prog, char *out, size_t len);

/* Build rpict's argv (NULL-terminated, malloc'd strings in a malloc'd array;
 * free with ps_render_free_argv). */
char **ps_render_argv(const char *rpict, const double pos[3], const double dir[3],
                      const double up[3], double field, int resolution, const char *options,
                      const char *octree);
void ps_render_free_argv(char **argv);
/* Wait for the renderer pid: 0 when it exited 0, else -1 with how it
 * ended in why ("exited with status N", "was killed by signal N"). */
int ps_render_reap(pid_t pid, char *why, size_t len);
/* Run argv with stdout into out_path (through a temporary file renamed on
 * success); -1 with a message naming the program and its exit status. */
int ps_render_run(char *const argv[], const char *out_path, struct ps_err *e);

#endif
