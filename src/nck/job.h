/* A job: a program, an MDI line or a list of moves, run on its own thread. */
#ifndef NCPAR_NCK_JOB_H
#define NCPAR_NCK_JOB_H

#include "job_msgs.h"

struct nck_core;

enum nck_job_kind { NCK_JOB_NONE, NCK_JOB_PROGRAM, NCK_JOB_MDI, NCK_JOB_MOVE };
#define NCK_JOB_MOVES 4

/* job.c */
int nck_job_start(struct nck_core *n);
void nck_job_join(struct nck_core *n);
/* a line from the map's position to end, traverse or at feed mm/s */
void nck_line(const struct nck_core *n, struct ncp_seg *s, const double from[NCP_AXES],
              const double to[NCP_AXES], double feed, int traverse);
/* what the status shows of an interpreter op: spindle, coolant, tool, G5x */
void nck_note_state(struct nck_core *n, const struct ncp_canon *op);

/* the job side: how the NCK takes a call (enum nck_call), and the queueing */
enum nck_call { NCK_CALL_MOTION, NCK_CALL_STATE, NCK_CALL_AUX, NCK_CALL_INFO, NCK_CALL_REFUSED };
int nck_call_class(const struct ncp_canon *op, const char *text);
const char *nck_call_what(int kind);
/* A call refused (d filled, its code returned) or taken (0), as the job will
 * take it: the batch run's pass before motion asks the same. */
int nck_check_call(const struct ncp_cmd *cmd, const struct ncp_canon *op, struct ncp_diag *d);

/* user_m.c: M100..M199's program, run once the machine is at rest; 0
 * when it exited 0, else -1 (the job's map_diag says why, unless the job
 * was aborted meanwhile) */
int nck_user_m_run(struct nck_core *n, const struct ncp_cmd *cmd, const struct ncp_canon *op);

#endif
