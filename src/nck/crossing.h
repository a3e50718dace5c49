/* What crosses the NCK's threads: the rings between them, the request and
 * acknowledge counters, and the results one thread hands another. Each
 * member says who writes it and who reads it. Nothing here blocks the
 * position loop: it uses only the rings and the atomics. */
#ifndef NCPAR_NCK_CROSSING_H
#define NCPAR_NCK_CROSSING_H

#include "cycle.h"
#include "homing.h"
#include "job_msgs.h"
#include "probe.h"

#include <pthread.h>

/* NCK_LF_TIMING: a miss limit tripped; NCK_LF_JOINT: a joint commanded
 * beyond its limit (fault_axis the joint, fault_err the position) */
enum nck_loop_fault { NCK_LF_NONE, NCK_LF_FERROR, NCK_LF_BACKEND, NCK_LF_TIMING, NCK_LF_JOINT };

/* What the interpreter last set that the machine does not act on yet, for
 * the status (guarded by ev_lock: the job thread writes, the caller reads). */
struct nck_io {
    double speed;
    int dir, mist, flood, tool, g5x_index;
    double g5x[6];
    uint32_t interp_line;
    struct ncp_active_codes active;  /* as of interp_line's slot */
};

#define NCK_EVENTS 256

struct nck_cross {
    /* rings, each one producer and one consumer: segs job -> planner, sps
     * planner -> loop, fbs loop -> caller (a cycle each), auxq machine
     * function packs and syncq synchronised runs job -> loop */
    struct ncp_spsc segs, sps, fbs, auxq, syncq;

    /* Stream marks: END/SYNC messages sent (job), END setpoints pushed
     * (planner), END setpoints reached (loop). A job's motion is complete when
     * ends_taken reaches the marks it sent. The caller resets marks_sent at
     * an unpark, while the job is ended and the planner parked. */
    _Atomic uint64_t marks_sent, ends_pushed, ends_taken;
    _Atomic int64_t end_ns;          /* loop -> caller: machine time of the last END commanded
                                        (a serving NCK's program time ends there) */

    /* The steps of dropping what is queued (stop, abort, E-stop, fault),
     * each a req the caller counts and an ack the other side counts: park
     * the planner, discard the setpoint ring (loop), start the planner again. */
    _Atomic int park_req, park_ack;
    _Atomic int discard_req, discard_ack;
    _Atomic int discard_to_actual;   /* caller, before discard_req: rest at the actual position */
    double rest[NCP_AXES];           /* loop, before discard_ack; planner and caller after it */
    _Atomic int unpark_req, unpark_ack;
    _Atomic int full_decel;          /* caller -> loop: abort holds at the axes' full deceleration */
    _Atomic int frozen;              /* caller -> loop: E-stop / fault, setpoints frozen, drives off */
    _Atomic int quit;                /* caller -> planner: leave */
    _Atomic int job_pending;         /* caller -> loop, batch --home: the program's job starts
                                        after homing; the loop holds still (virtual clock: time too) */
    _Atomic int job_waiting;         /* job -> loop: at a block end, waiting for resume */

    /* the loop's fault: it writes the details, then loop_fault (release);
     * the caller reads them after loop_fault (acquire) and clears it at a reset */
    _Atomic int loop_fault;          /* enum nck_loop_fault */
    int fault_axis;
    double fault_err;
    uint32_t fault_line;
    _Atomic int at_rest;             /* loop -> caller: rate 0 or the stream at a stop */
    _Atomic uint64_t pub_misses;     /* loop -> caller: the status's deadline misses */
    _Atomic int64_t pub_lat_max_ns;
    /* the timing faults' report: the loop writes it; the caller reads it
     * once the loop has ended, or after loop_fault */
    struct ncp_inject_report inj_rep;

    /* the probe's result (probe.h) */
    struct nck_probe_result probe;
    /* #5399 as the loop found it at an M66: written before the AUX stop's
     * END counts in ends_taken, read by the job after that */
    double m66_result;
    /* homing's request and result (homing.h) */
    struct nck_home_req home;

    /* canonical calls the jobs took, acted on and refused, per kind: job
     * threads, in turn; the caller reads them after the job */
    uint64_t calls_in[NCP_C__COUNT], calls_acted[NCP_C__COUNT], calls_refused[NCP_C__COUNT];
    /* ring and task timing for the trace (TRACE_RINGS): each written by its
     * task, read by the loop into the cycle */
    _Atomic int64_t plan_resp_ns, plan_cycle_ns, job_cycle_ns;

    /* events, oldest first, and the status's view of the interpreter: the
     * job thread and the caller's thread, under ev_lock */
    pthread_mutex_t ev_lock;
    struct ncp_nck_event ev[NCK_EVENTS];
    unsigned ev_head, ev_count;
    uint64_t ev_dropped;
    int post_prints;                 /* set before start: PRINT/MSG/DEBUG as events, not stderr */
    struct nck_io io;

    /* the backend: opened and started by the caller before the loop starts,
     * cycled by the loop; the planner thread calls the plan taps and journal
     * it set at open (hooks made for that thread); the caller asks it why it
     * faulted only after loop_fault, and stops and closes it after the join */
    struct ncp_backend be;
    /* the position loop's thread: the caller starts and joins it, asks it
     * to stop and sees it running (its atomics); fifo and warning are set
     * before it starts cycling; its statistics are the loop's, read by the
     * caller after the join */
    struct ncp_rt_loop rt;

    /* [SCHED] (sched.c): set up by the caller before start; then each task
     * (task 0 the job thread, task 1 the planner, the interpreter pipeline's
     * threads) enters and leaves its own slot and notes the priority it got
     * (prio_seen); the scheduler thread moves priorities (src/sched) */
    struct ncp_sched sched;
    struct ncp_rt_place job_place, planner_place;
    _Atomic int prio_seen[NCP_SCHED_TASKS];
    struct ncp_pipe_thread pipe_thread[NCP_SCHED_TASKS];
    struct ncp_pipe_hooks pipe_hooks;
};

#endif
