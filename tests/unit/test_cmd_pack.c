/* Packed commands (the analyzer -> output hand-off with no executor threads):
 * what formatting and emitting read survives packing, nothing is written past
 * a record, and the filler is told apart from every command. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "../../src/pipeline/cmd_pack.h"
#include "ncpar/diag.h"
#include "ncpar/executor.h"

static void fill(struct ncp_cmd *c, uint64_t seed)
{
    memset(c, 0, sizeof *c);
    c->cmd_id = seed * 7919u;
    c->line = (uint32_t)(seed % 100000u);
    c->n_ops = (uint16_t)(seed % (NCP_CMD_MAX_OPS + 1));
    c->flags = (uint16_t)(seed % 8u);
    c->text_used = (uint16_t)(seed * 37u % (NCP_CMD_TEXT_POOL + 1));
    for (unsigned k = 0; k < c->n_ops; k++) {
        c->ops[k].kind = (uint16_t)(k + seed % 50u);
        c->ops[k].text_off = (uint16_t)k;
        c->ops[k].text_len = (uint16_t)(seed % 13u);
        for (int i = 0; i < NCP_CANON_NI; i++)
            c->ops[k].raw.i[i] = (int32_t)(seed * 31u + (uint64_t)i);
        for (int d = 0; d < NCP_CANON_ND; d++)
            c->ops[k].raw.d[d] = (double)seed / (d + 1.5);
    }
    for (unsigned t = 0; t < c->text_used; t++)
        c->text[t] = (char)('a' + (seed + t) % 26u);
    if (c->flags & NCP_CMD_F_ERROR) {
        size_t n = seed % (NCP_DIAG_MSG_MAX - 1);
        ncp_diag_set(&c->diag, NCP_ERR_SYNTAX, c->line, (uint32_t)(seed % 80u), "%s", "");
        memset(c->diag.msg, 'm', n);
        c->diag.msg[n] = '\0';
    }
}

static void test_round_trip(void **state)
{
    (void)state;
    static struct ncp_cmd in, out;
    static union {
        struct ncp_cmd c;
        unsigned char b[NCP_CMD_PACK_MAX + 64];
    } slot;
    unsigned char *buf = slot.b;
    for (uint64_t seed = 0; seed < 3000; seed++) {
        fill(&in, seed);
        size_t want = ncp_cmd_packed_size(&in);
        /* the analyzer writes the command into its slot (what a command
         * writes, not its executor output), and packs it there */
        memset(buf, 0xA5, sizeof slot.b);
        memcpy(buf, &in, NCP_CMD_IN_PLACE_BYTES);
        assert_int_equal(ncp_cmd_pack_in_place(&slot.c), want);
        assert_true(want % 8 == 0 && want <= NCP_CMD_IN_PLACE_BYTES);
        /* nothing written past the slot's room */
        assert_int_equal(buf[NCP_CMD_IN_PLACE_BYTES], 0xA5);
        assert_int_equal(ncp_cmd_packed_units(buf) * 8, want);
        /* the inline calls-only path makes the record the general one makes */
        static union {
            struct ncp_cmd c;
            unsigned char b[NCP_CMD_PACK_MAX + 64];
        } general;
        memset(general.b, 0xA5, sizeof general.b);
        memcpy(general.b, &in, NCP_CMD_IN_PLACE_BYTES);
        assert_int_equal(ncp_cmd_pack_general(&general.c), want);
        assert_memory_equal(general.b, buf, want);
        assert_false(ncp_cmd_packed_is_pad(buf));
        memset(&out, 0x5A, sizeof out);
        ncp_cmd_unpack(buf, &out);
        assert_int_equal(out.cmd_id, in.cmd_id);
        assert_int_equal(out.line, in.line);
        assert_int_equal(out.n_ops, in.n_ops);
        assert_int_equal(out.flags, in.flags);
        assert_int_equal(out.text_used, in.text_used);
        assert_int_equal(out.out_len, 0);
        if (in.n_ops)
            assert_memory_equal(out.ops, in.ops, in.n_ops * sizeof in.ops[0]);
        if (in.text_used)
            assert_memory_equal(out.text, in.text, in.text_used);
        if (in.flags & NCP_CMD_F_ERROR) {
            assert_int_equal(out.diag.code, in.diag.code);
            assert_int_equal(out.diag.line, in.diag.line);
            assert_int_equal(out.diag.col, in.diag.col);
            assert_string_equal(out.diag.msg, in.diag.msg);
        }
    }
    unsigned char pad[8];
    ncp_cmd_pack_pad(pad);
    assert_true(ncp_cmd_packed_is_pad(pad));
}

/* An arc request in the XY plane from (0, 0) to (2, 0): centre (1, 0) draws
 * it; in the radius form with the end at the start it is an error. */
static void arc_request(struct ncp_canon *op, int fails)
{
    memset(op, 0, sizeof *op);
    op->kind = NCP_C_ARC_REQUEST;
    op->arc.dir = 1;
    op->arc.turns = 1;
    op->arc.first_end = fails ? 0.0 : 2.0;
    op->arc.radius_form = fails;
    if (fails)
        op->arc.radius = 1.0;
    else
        op->arc.first_centre = 1.0;
}

static void calls_only_cmd(struct ncp_cmd *c, unsigned n_ops, int arc_fails)
{
    memset(c, 0, sizeof *c);
    c->cmd_id = 41;
    c->line = 17;
    c->n_ops = (uint16_t)n_ops;
    for (unsigned k = 0; k < n_ops; k++) {
        c->ops[k].kind = NCP_C_STRAIGHT_FEED;
        for (int d = 0; d < 6; d++)
            c->ops[k].move.end[d] = k + d * 0.25;
    }
    if (arc_fails >= 0)
        arc_request(&c->ops[n_ops - 1], arc_fails);
}

/* The output thread executes a calls-only record where it stands in the
 * ring: it must come out as the unpacked command does, and an error found
 * there must go to the slot it is given, never past the record (those bytes
 * belong to the records after it). */
static void test_execute_in_place(void **state)
{
    (void)state;
    static struct ncp_cmd in, own, ref;
    static union {
        struct ncp_cmd c;
        unsigned char b[NCP_CMD_PACK_MAX + 64];
    } slot;
    static char text[NCP_CMD_OUT_MAX], want[NCP_CMD_OUT_MAX];
    for (unsigned n = 1; n <= NCP_CMD_MAX_OPS; n++) {
        for (int arc = -1; arc <= 1; arc++) {
            calls_only_cmd(&in, n, arc);
            memset(slot.b, 0xA5, sizeof slot.b);
            memcpy(slot.b, &in, NCP_CMD_IN_PLACE_BYTES);
            size_t size = ncp_cmd_pack_in_place(&slot.c);
            assert_true(ncp_cmd_packed_calls_only(slot.b));
            memset(slot.b + size, 0xA5, sizeof slot.b - size); /* the next records */
            ncp_cmd_unpack(slot.b, &ref);
            int ref_rc = ncp_exec_cmd_into(&ref, want);
            memset(&own, 0, sizeof own);
            int rc = ncp_exec_cmd_into_diag(&slot.c, text, &own.diag);
            assert_int_equal(rc, ref_rc);
            assert_int_equal(rc != NCP_OK, arc == 1);
            for (size_t i = size; i < sizeof slot.b; i++)
                assert_int_equal(slot.b[i], 0xA5);
            assert_int_equal(slot.c.out_len, ref.out_len);
            assert_memory_equal(text, want, ref.out_len);
            ncp_cmd_copy_calls(&slot.c, &own);
            assert_int_equal(own.cmd_id, ref.cmd_id);
            assert_int_equal(own.line, ref.line);
            assert_int_equal(own.n_ops, ref.n_ops);
            assert_int_equal(own.flags, ref.flags);
            assert_int_equal(own.out_len, ref.out_len);
            if (ref.n_ops)
                assert_memory_equal(own.ops, ref.ops, ref.n_ops * sizeof ref.ops[0]);
            if (rc != NCP_OK) {
                assert_int_equal(own.diag.code, ref.diag.code);
                assert_int_equal(own.diag.line, ref.diag.line);
                assert_string_equal(own.diag.msg, ref.diag.msg);
            }
        }
    }
    /* an error or text: not executed where it stands */
    calls_only_cmd(&in, 1, -1);
    in.text_used = 3;
    memcpy(slot.b, &in, NCP_CMD_IN_PLACE_BYTES);
    ncp_cmd_pack_in_place(&slot.c);
    assert_false(ncp_cmd_packed_calls_only(slot.b));
    calls_only_cmd(&in, 1, -1);
    in.flags = NCP_CMD_F_ERROR;
    ncp_diag_set(&in.diag, NCP_ERR_SYNTAX, 17, 1, "bad");
    memcpy(slot.b, &in, NCP_CMD_IN_PLACE_BYTES);
    ncp_cmd_pack_in_place(&slot.c);
    assert_false(ncp_cmd_packed_calls_only(slot.b));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_execute_in_place),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
