/* libFuzzer target for the whole interpreter: any byte string is a program.
 * Beyond "no crash, no hang, no leak", it is differential: the parallel pipeline
 * must produce the same canonical text and the same first error as the serial
 * reference, for every input. */
#include "ncpar/pipeline.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct capture {
    size_t len, cap;
    char *buf;
};

static int capture_emit(void *ctx, const struct ncp_cmd *cmd)
{
    struct capture *c = ctx;
    if (c->len + cmd->out_len > c->cap) {
        size_t cap = (c->cap ? c->cap * 2 : 1 << 16) + cmd->out_len;
        char *p = realloc(c->buf, cap);
        if (!p)
            return 1;
        c->buf = p;
        c->cap = cap;
    }
    memcpy(c->buf + c->len, cmd->out, cmd->out_len);
    c->len += cmd->out_len;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct ncp_source src;
    struct ncp_diag d1, d2;
    struct ncp_run_stats st;
    /* small limits keep runaway loops short while still exercising the guard */
    struct ncp_analyzer_cfg cfg = { .max_loop_iterations = 2000 };
    struct capture serial = { 0 }, par = { 0 };
    struct ncp_output o1 = { .ctx = &serial, .emit = capture_emit },
                      o2 = { .ctx = &par, .emit = capture_emit };

    memset(&d1, 0, sizeof d1);
    memset(&d2, 0, sizeof d2);
    ncp_source_from_memory(&src, (const char *)data, size, "fuzz", &d1);
    int rc1 = ncp_serial_run(&src, &cfg, &o1, &st, &d1);

    struct ncp_thread_map map;
    /* lexers 0..2 (0: the analyzer lexes), executors 0..2 (0: the output formats) */
    ncp_thread_map_default(&map, NCP_MODE_DET, (int)(size / 6 % 3), (int)(size % 3));
    map.inline_output = size % 6 == 3; /* with 0 executors half the time: the analyzer writes */
    /* tiny rings: every input wraps them, and the run stays cheap */
    map.string_rows = 2;
    map.parsed_rows = 2;
    map.cmd_slots = 4;
    /* -j 0 with packed output: the output thread lexes ahead in chunks of a
     * line or two (the default 8 KB chunk is larger than any fuzz input) */
    map.lex_ahead_bytes = 16 + (int)(size % 48);
    int rc2 = ncp_pipeline_run(&src, &map, &cfg, &o2, &st, &d2);

    if (rc1 != rc2 || serial.len != par.len || memcmp(serial.buf, par.buf, serial.len) ||
        d1.line != d2.line || d1.col != d2.col || strcmp(d1.msg, d2.msg))
        abort();
    free(serial.buf);
    free(par.buf);
    return 0;
}
