/* The serial reference: the very same stage code as the parallel pipeline, called
 * in one thread without rings. Every parallel configuration must equal it. */
#include "ncpar/executor.h"
#include "ncpar/lex.h"
#include "ncpar/pipeline.h"
#include "emit.h"
#include "pipe.h"
#include "ncpar/blocks.h"
#include "ncpar/clock.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

struct serial_sink {
    const struct ncp_output *out;
    uint64_t next_id;
    uint64_t emitted;
    int stopped;       /* an error/end slot went out, or emit() asked to stop */
    int emit_failed;
    struct ncp_diag err;
    struct ncp_cmd cmd;
};

/* Only the header is cleared: ops are written whole by the analyzer. */
void ncp_cmd_reset_header(struct ncp_cmd *cmd, uint64_t id)
{
    cmd->cmd_id = id;
    cmd->line = 0;
    cmd->n_ops = 0;
    cmd->flags = 0;
    cmd->text_used = 0;
    cmd->out_len = 0;
}

static struct ncp_cmd *serial_acquire(void *ctx)
{
    struct serial_sink *s = ctx;
    if (s->stopped)
        return NULL;
    ncp_cmd_reset_header(&s->cmd, s->next_id++);
    return &s->cmd;
}

static void serial_publish(void *ctx, struct ncp_cmd *cmd)
{
    struct serial_sink *s = ctx;
    s->emitted++;
    if (ncp_exec_emit_cmd(cmd, s->out, &s->err, &s->emit_failed))
        s->stopped = 1;
}

int ncp_serial_run(const struct ncp_source *src, const struct ncp_analyzer_cfg *acfg,
                   const struct ncp_output *out, struct ncp_run_stats *stats,
                   struct ncp_diag *d)
{
    double t0 = (double)ncp_mono_ns() / 1e6, cpu0 = ncp_pipe_thread_cpu_ms();
    double sys0 = ncp_pipe_thread_sys_ms();
    struct ncp_text_feed *feed = malloc(sizeof *feed);
    struct serial_sink *sink = malloc(sizeof *sink);
    struct ncp_analyzer *an = NULL;
    int rc;

    memset(d, 0, sizeof *d);
    if (feed)
        feed->blocks = 0;
    if (sink)
        sink->emitted = 0;
    if (!feed || !sink) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
        goto done;
    }
    ncp_text_feed_start(feed, src);
    sink->out = out;
    sink->next_id = 0;
    sink->emitted = 0;
    sink->stopped = 0;
    sink->emit_failed = 0;
    sink->err.code = NCP_OK;

    an = acfg && acfg->instance ? acfg->instance : ncp_analyzer_new(acfg, d);
    if (!an) {
        rc = d->code ? d->code : NCP_ERR_IO;
        goto done;
    }
    struct ncp_block_feed bf = { feed, ncp_text_feed_next, ncp_text_feed_release, src };
    struct ncp_cmd_sink cs = { sink, serial_acquire, serial_publish };
    /* each command is emitted as it is published: nothing to hand on first */
    ncp_analyzer_set_sync(an, out ? out->sync : NULL, out ? out->ctx : NULL);
    rc = ncp_analyzer_run(an, &bf, &cs);
    ncp_analyzer_set_sync(an, NULL, NULL);
    if (sink->err.code != NCP_OK) {
        *d = sink->err;
        rc = d->code;
    } else if (sink->emit_failed) {
        rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot write output");
    } else if (rc != NCP_OK && rc != NCP_END) {
        ncp_diag_set(d, (enum ncp_status)rc, 0, 0, "interpreter stopped without a diagnostic");
    } else {
        rc = NCP_OK;
    }
done:
    if (stats) {
        stats->blocks = feed ? feed->blocks : 0;
        stats->commands = sink ? sink->emitted : 0;
        stats->wall_ms = (double)ncp_mono_ns() / 1e6 - t0;
        stats->threads = 1;
        /* the one thread does every stage's work: the parallel layouts' CPU
         * time per stage is read against this */
        stats->analyzer.cpu_ms = ncp_pipe_thread_cpu_ms() - cpu0;
        stats->analyzer.wall_ms = stats->wall_ms;
        stats->analyzer.sys_ms = ncp_pipe_thread_sys_ms() - sys0;
        stats->analyzer.items = stats->blocks;
    }
    if (!acfg || an != acfg->instance)
        ncp_analyzer_free(an);
    free(feed);
    free(sink);
    return rc;
}
