/* SPDX-License-Identifier: ISC */
/* For the DALI USB tests: make sure libumockdev-preload.so.0 is loaded, by
 * re-executing the test under LD_PRELOAD (tests/run.sh runs programs
 * directly); exit 77 with the reason when it cannot be. */
#ifndef PS_TEST_DALI_PRELOAD_H
#define PS_TEST_DALI_PRELOAD_H

void ps_test_need_umockdev(char **argv);

#endif
