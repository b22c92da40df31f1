/* Calibration sessions in the sample log's SQLite database: versioned
 * records (schema in meta 'cal_schema'), every sample committed as it is
 * taken, accepted calibrations kept with their history. */
#ifndef PSD_CALSTORE_H
#define PSD_CALSTORE_H

#include <stddef.h>

struct sqlite3;

/* Create the tables when missing; -1 with a message. */
int psd_calstore_init(struct sqlite3 *h, char *err, size_t errlen);
/* A new running session; its id, or -1 with a message. */
long long psd_calstore_begin(struct sqlite3 *h, const char *zone, const char *kind, double started,
                             const char *config_sha256, const char *scene_sha256, char *err, size_t errlen);
int psd_calstore_sample(struct sqlite3 *h, long long id, int seq, double t, double level, double volts,
                        double volts_se, double lux, const char *source, char *err, size_t errlen);
/* End a session: state done, aborted; results (JSON) and a note. */
int psd_calstore_end(struct sqlite3 *h, long long id, const char *state, double ended, const char *results,
                     const char *note, char *err, size_t errlen);
/* Accept a done session: the zone's previous accepted one of that kind
 * becomes 'superseded'. */
int psd_calstore_accept(struct sqlite3 *h, long long id, char *err, size_t errlen);

/* The zone's running session, if any: id, kind and start time; 0 found,
 * 1 none, -1 error. */
int psd_calstore_running(struct sqlite3 *h, const char *zone, long long *id, char *kind, size_t kindlen,
                         double *started);
typedef void (*psd_calstore_sample_fn)(void *user, double t, double level, double volts, double volts_se,
                                       double lux);
/* Every sample of a session in order. */
int psd_calstore_samples(struct sqlite3 *h, long long id, psd_calstore_sample_fn fn, void *user);
/* The results (JSON, malloc'd) of the zone's accepted session of a kind, or NULL. */
char *psd_calstore_accepted(struct sqlite3 *h, const char *zone, const char *kind, long long *id);

#endif
