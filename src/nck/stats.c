/* The consumer of the position loop's cycles: trace rows, following and
 * contour error, the live progress line and the final summary. Runs on the
 * caller's thread, never on the real-time one. */
#include "nck_int.h"
#include "service_state.h"

#include <errno.h>
#include <math.h>
#include <string.h>
#include <unistd.h>

/* Squared, so that the search below takes one square root, not one per
 * segment (it runs for 64 segments every cycle: a fifth of a virtual-clock
 * run's time went here). */
static double dist2_to_seg(const double p[NCP_AXES], const double a[NCP_AXES],
                           const double b[NCP_AXES])
{
    double ab2 = 0, ap_ab = 0, d2 = 0;
    for (int j = 0; j < 3; j++) {
        ab2 += (b[j] - a[j]) * (b[j] - a[j]);
        ap_ab += (p[j] - a[j]) * (b[j] - a[j]);
    }
    double f = ab2 > 0 ? ap_ab / ab2 : 0;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    for (int j = 0; j < 3; j++) {
        double q = a[j] + f * (b[j] - a[j]) - p[j];
        d2 += q * q;
    }
    return d2;
}

/* Distance from the actual point to the commanded path in X Y Z (the tool
 * tip on a machine with trivial kinematics), taken as the polyline
 * of the recent commanded samples (its chord error is v^2 T^2 / 8r). */
static double contour_error(struct nck_summary *s, const struct nck_fb *fb)
{
    memcpy(s->hist[s->hist_at], fb->cmd, sizeof s->hist[0]);
    s->hist_at = (s->hist_at + 1) % NCK_CONTOUR_HISTORY;
    if (s->hist_n < NCK_CONTOUR_HISTORY)
        s->hist_n++;
    if (s->hist_n < 2)
        return sqrt(dist2_to_seg(fb->act, fb->cmd, fb->cmd));
    double best = INFINITY;
    for (size_t k = 1; k < s->hist_n; k++) {
        size_t i = (s->hist_at + NCK_CONTOUR_HISTORY - k) % NCK_CONTOUR_HISTORY;
        size_t i0 = (i + NCK_CONTOUR_HISTORY - 1) % NCK_CONTOUR_HISTORY;
        double d2 = dist2_to_seg(fb->act, s->hist[i0], s->hist[i]);
        if (d2 < best)
            best = d2;
    }
    return sqrt(best);
}

/* Trace column `motion`: 0 rapid (G0), 1 feed (G1, corner blends, rest),
 * 2 arc (G2/G3, helices), 3 synchronised with the spindle (G33, G33.1, G76). */
static int nck_motion_column(uint32_t flags)
{
    return flags & NCP_SP_SYNC ? 3 : flags & NCP_SP_RAPID ? 0 : flags & NCP_SP_ARC ? 2 : 1;
}

/* ",cmd,act" for each axis of mask from axis `from` on. */
static int trace_pairs(char *buf, size_t len, unsigned mask, int from, const double cmd[NCP_AXES],
                       const double act[NCP_AXES])
{
    size_t at = 0;
    for (int j = from; j < NCP_AXES; j++) {
        if (!(mask & NCP_AXIS_BIT(j)))
            continue;
        int k = snprintf(buf + at, len - at, ",%.6f,%.6f", cmd[j], act[j]);
        if (k < 0 || (size_t)k >= len - at)
            return -1;
        at += (size_t)k;
    }
    return (int)at;
}

/* The rows' columns for the axes beyond X Y Z the machine has, after all
 * the others, so that readers of the fixed columns keep working. */
static int trace_more_axes(char *buf, size_t len, unsigned mask, const struct nck_fb *fb)
{
    return trace_pairs(buf, len, mask, 3, fb->cmd, fb->act);
}

/* The joints, after everything else, under non-trivial kinematics: the
 * tool length the transform used, then what the servos were told and did,
 * to compute the tool tip back from. */
static int trace_joints(char *buf, size_t len, unsigned mask, const struct nck_fb *fb)
{
    int k0 = snprintf(buf, len, ",%.6f", fb->tool_z);
    if (k0 < 0 || (size_t)k0 >= len)
        return -1;
    int k = trace_pairs(buf + k0, len - (size_t)k0, mask, 0, fb->jcmd, fb->jact);
    return k < 0 ? -1 : k0 + k;
}

/* The `home` column: one digit per machine axis, in COORDINATES
 * order, the homing phase it is in (enum nck_home_phase, 0 not homing). */
static int trace_home(char *buf, size_t len, unsigned mask, uint64_t home)
{
    size_t at = 0;
    if (len < 2 + NCP_AXES)
        return -1;
    buf[at++] = ',';
    for (int j = 0; j < NCP_AXES; j++)
        if (mask & NCP_AXIS_BIT(j))
            buf[at++] = (char)('0' + ((home >> (4 * j)) & 0xf));
    return (int)at;
}

static int ring_columns(char *buf, size_t len, const struct nck_summary *s,
                        const struct nck_fb *fb)
{
    int k = snprintf(buf, len, ",%u,%u,%u,%u,%.1f,%.1f,%.1f,%.1f", fb->seg_fill, s->seg_cap,
                     fb->sp_fill, s->sp_cap, (double)fb->job_cycle_ns * 1e-3,
                     (double)fb->plan_resp_ns * 1e-3, (double)fb->plan_cycle_ns * 1e-3,
                     (double)fb->loop_cycle_ns * 1e-3);
    return k > 0 && (size_t)k < len ? k : -1;
}

void nck_account(struct nck_summary *s, unsigned mask, const struct nck_fb *fb, FILE *trace)
{
    double e2 = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        double e = fb->cmd[j] - fb->act[j];
        if (j < 3)   /* mm: the tool's following error */
            e2 += e * e;
        s->ferr_axis_max[j] = fmax(s->ferr_axis_max[j], fabs(e));
    }
    /* the path as LinuxCNC measures it: along X Y Z, else along A B C */
    double e = sqrt(e2), c = contour_error(s, fb), step = 0, turn = 0;
    for (int j = 0; j < 6 && s->rows; j++) {
        double d = (fb->cmd[j] - s->last[j]) * (fb->cmd[j] - s->last[j]);
        if (j < 3)
            step += d;
        else
            turn += d;
    }
    s->path += step > 0 ? sqrt(step) : sqrt(turn);
    memcpy(s->last, fb->cmd, sizeof s->last);
    s->rows++;
    s->ferr_max = fmax(s->ferr_max, e);
    s->job_ferr_max = fmax(s->job_ferr_max, e);
    for (int j = 0; j < NCP_AXES; j++) {
        s->ext_min[j] = s->rows > 1 ? fmin(s->ext_min[j], fb->cmd[j]) : fb->cmd[j];
        s->ext_max[j] = s->rows > 1 ? fmax(s->ext_max[j], fb->cmd[j]) : fb->cmd[j];
    }
    s->contour_max = fmax(s->contour_max, c);
    if (fb->v > 0) {
        s->moving++;
        s->ferr_sum += e;
        s->contour_sum += c;
    }
    s->line = fb->line;
    s->rpm_max = fmax(s->rpm_max, fabs(fb->rpm));
    memcpy(s->act, fb->act, sizeof s->act);
    s->t = fb->t;
    s->v = fb->v;
    if (!trace)
        return;
    if (sizeof s->tbuf - s->tlen < 1024)   /* room for the widest row */
        nck_trace_flush(s, trace);
    /* the machine functions after the axes: readers of the first ten
     * columns keep working */
    double deg = 360 * (fb->rev - floor(fb->rev));
    int k = snprintf(s->tbuf + s->tlen, sizeof s->tbuf - s->tlen,
                     "%.6f,%u,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%d,%.3f,%.3f,%d,%d,%llu,%d,%d\n",
                     fb->t, fb->line, fb->cmd[0], fb->cmd[1], fb->cmd[2], fb->act[0], fb->act[1],
                     fb->act[2], fb->v, nck_motion_column(fb->flags), fb->rpm, deg, fb->mist,
                     fb->flood, (unsigned long long)fb->dout, fb->tool, fb->wait);
    if (k > 0 && (size_t)k < sizeof s->tbuf - s->tlen) {
        size_t at = s->tlen + (size_t)k - 1;   /* the row's newline */
        int m = (mask & ~NCP_AXES_XYZ) ? trace_more_axes(s->tbuf + at, sizeof s->tbuf - at - 1,
                                                         mask, fb)
                                       : 0;
        /* the spindle's angle in turns, counted on (not wrapped): the
         * synchronised moves are checked against it */
        if (m >= 0) {
            int t = snprintf(s->tbuf + at + m, sizeof s->tbuf - at - (size_t)m - 1, ",%.9f",
                             fb->rev);
            m = t > 0 && (size_t)t < sizeof s->tbuf - at - (size_t)m - 1 ? m + t : -1;
        }
        /* every axis's homing phase */
        int h = m >= 0 ? trace_home(s->tbuf + at + m, sizeof s->tbuf - at - (size_t)m - 1, mask,
                                    fb->home)
                       : -1;
        m = h >= 0 ? m + h : -1;
        if (m >= 0 && s->joints) {
            int mj = trace_joints(s->tbuf + at + (size_t)m, sizeof s->tbuf - at - (size_t)m - 1,
                                  mask, fb);
            m = mj < 0 ? -1 : m + mj;
        }
        /* the inject column, then the ring columns come last */
        if (m >= 0 && s->inject_col) {
            at += (size_t)m;
            s->tbuf[at++] = ',';
            m = ncp_inject_format(&fb->inj, s->tbuf + at, sizeof s->tbuf - at - 1);
        }
        if (m >= 0 && s->rings) {
            at += (size_t)m;
            m = ring_columns(s->tbuf + at, sizeof s->tbuf - at - 1, s, fb);
        }
        if (m >= 0) {
            s->tbuf[at + (size_t)m] = '\n';
            s->tlen = at + (size_t)m + 1;
        }
    }
}

void nck_trace_header(FILE *trace, const struct ncp_machine_cfg *cfg, int joints, int rings)
{
    unsigned mask = cfg->axis_mask;
    fputs("t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion,spindle_rpm,spindle_deg,mist,"
          "flood,dout,tool,wait", trace);
    for (int j = 3; j < NCP_AXES; j++)
        if (mask & NCP_AXIS_BIT(j))
            fprintf(trace, ",%c_cmd,%c_act", NCP_AXIS_LETTERS[j] | 0x20,
                    NCP_AXIS_LETTERS[j] | 0x20);
    fputs(",spindle_turns,home", trace);
    if (joints)
        fputs(",tool_z", trace);
    for (int j = 0; j < NCP_AXES && joints; j++)
        if (mask & NCP_AXIS_BIT(j))
            fprintf(trace, ",j%c_cmd,j%c_act", NCP_AXIS_LETTERS[j] | 0x20,
                    NCP_AXIS_LETTERS[j] | 0x20);
    /* what was injected in the period: "-", or e.g. "miss+jit=12.500" */
    if (cfg->inject.kinds)
        fputs(",inject", trace);
    /* the soft-RT chain: segment ring (job -> planner), setpoint ring
     * (planner -> position loop), each task's last cycle, in us */
    if (rings)
        fputs(",seg_fill,seg_cap,sp_fill,sp_cap,job_cycle_us,plan_resp_us,plan_cycle_us,"
              "loop_cycle_us", trace);
    fputc('\n', trace);
    fflush(trace);
}

/* A write cut short (a full disk takes what fits) leaves part of a row:
 * the file is cut back to the end of the last whole row, which frees the
 * room it needs. */
static void trace_cut_to_rows(const struct nck_summary *s, int fd, size_t done)
{
    const char *nl = memrchr(s->tbuf, '\n', done);
    size_t torn = done - (nl ? (size_t)(nl - s->tbuf) + 1 : 0);
    off_t end = lseek(fd, 0, SEEK_CUR);
    if (torn == 0 || end < (off_t)torn)
        return;
    if (ftruncate(fd, end - (off_t)torn) == 0)
        (void)lseek(fd, end - (off_t)torn, SEEK_SET);
}

int nck_trace_flush(struct nck_summary *s, FILE *trace)
{
    const char *p = s->tbuf;
    const size_t all = s->tlen;
    size_t left = all;
    s->tlen = 0;
    if (s->trace_errno)   /* it ended early: no rows after a gap */
        return -1;
    while (left > 0) {
        ssize_t w = write(fileno(trace), p, left);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            s->trace_errno = w < 0 ? errno : ENOSPC;
            trace_cut_to_rows(s, fileno(trace), all - left);
            return -1;
        }
        p += w;
        left -= (size_t)w;
    }
    return 0;
}

int nck_read_cycles(struct nck_core *n)
{
    struct nck_fb fb;
    int got = 0;
    while (ncp_spsc_pop(&n->cross.fbs, &fb) == 0) {
        nck_account(&n->svc->sum, n->cfg->axis_mask, &fb, n->setup.trace);
        n->svc->sum.job_done_s += fb.adv * n->cfg->servo_period;
        if (fb.waits != n->svc->last_fb.waits && fb.wait != NCK_WAIT_NONE)
            nck_wait_began(n, &fb);
        n->svc->last_fb = fb;
        n->svc->have_fb = 1;
        got++;
    }
    return got;
}

/* cyclictest-like histogram, folded into a few readable buckets for a terminal. */
static void print_latency(const struct ncp_rt_stats *st, FILE *f)
{
    static const int edges[] = { 5, 10, 20, 50, 100, 200, 500, NCP_RT_HIST_BINS };
    if (!st->cycles) {
        fprintf(f, "  loop latency: no cycles\n");
        return;
    }
    fprintf(f, "  loop latency: min %.1f us, avg %.1f us, max %.1f us over %llu cycles\n",
            (double)st->lat_min_ns / 1e3, st->lat_sum_ns / (double)st->cycles / 1e3,
            (double)st->lat_max_ns / 1e3, (unsigned long long)st->cycles);
    fprintf(f, "  latency histogram:");
    int lo = 0;
    for (size_t e = 0; e < sizeof edges / sizeof edges[0]; e++) {
        uint64_t n = 0;
        for (int i = lo; i < edges[e]; i++)
            n += st->hist[i];
        fprintf(f, " %d-%dus %llu%s", lo, edges[e], (unsigned long long)n, ",");
        lo = edges[e];
    }
    fprintf(f, " >=%dus %llu\n", NCP_RT_HIST_BINS, (unsigned long long)st->overflow);
}

void ncp_nck_print_summary(const struct ncp_nck_result *r, const char *prog, FILE *f)
{
    fprintf(f, "%s: position loop %s%s\n", prog, r->fifo ? "SCHED_FIFO" : "SCHED_OTHER",
            r->warning[0] ? " (no real-time permission)" : "");
    fprintf(f, "  program time %.3f s%s, path length %.3f mm, %llu segments\n",
            r->program_time,
            r->interrupted ? " (interrupted: feed hold, braked along the path)"
            : r->for_expired ? " (--for: feed hold, braked along the path)" : "",
            r->path_length,
            (unsigned long long)r->segments);
    fprintf(f, "  following error: max %.4f mm (X %.4f, Y %.4f, Z %.4f), avg %.4f mm in motion\n",
            r->ferr_max, r->ferr_axis_max[0], r->ferr_axis_max[1], r->ferr_axis_max[2],
            r->ferr_avg);
    if (r->axis_mask & ~NCP_AXES_XYZ) {
        fprintf(f, "  following error of the other axes:");
        for (int j = 3; j < NCP_AXES; j++)
            if (r->axis_mask & NCP_AXIS_BIT(j))
                fprintf(f, " %c %.4f %s", NCP_AXIS_LETTERS[j], r->ferr_axis_max[j],
                        ncp_axis_rotary(j) ? "deg" : "mm");
        fputc('\n', f);
    }
    fprintf(f, "  contour error: max %.4f mm, avg %.4f mm in motion\n", r->contour_max,
            r->contour_avg);
    fprintf(f, "  canonical calls: %llu in, %llu acted on, %llu refused; spindle max %.0f rpm; "
               "%llu pauses\n",
            (unsigned long long)r->calls_in, (unsigned long long)r->calls_acted,
            (unsigned long long)r->calls_refused, r->spindle_rpm_max,
            (unsigned long long)r->pauses);
    print_latency(&r->lat, f);
    fprintf(f, "  deadline misses %llu (periods skipped %llu), underruns %llu (slowed along the path; "
               "%llu cycles held empty), planner waited %llu cycles\n",
            (unsigned long long)r->lat.misses, (unsigned long long)r->lat.skipped,
            (unsigned long long)r->underruns, (unsigned long long)r->dry,
            (unsigned long long)r->starved);
    if (r->starts)
        fprintf(f, "  start from rest: first setpoint %.1f ms, first move %.1f ms after the first "
                   "segment reached the planner (worst of %llu)\n",
                r->start_sp_max * 1e3, r->start_move_max * 1e3, (unsigned long long)r->starts);
    if (r->inject_summary[0])
        fprintf(f, "  %s\n", r->inject_summary);
    if (r->sched_summary[0])
        fprintf(f, "  sched: %s\n", r->sched_summary);
    if (r->trace_dropped)
        fprintf(f, "  trace: %llu cycles dropped (the writer fell behind)\n",
                (unsigned long long)r->trace_dropped);
}
