/* SPDX-License-Identifier: ISC */
/* The project's version, printed by the tools' -V/--version. */
#ifndef PS_VERSION_H
#define PS_VERSION_H

#ifndef PS_VERSION
#define PS_VERSION "0.1"
#endif

#endif
