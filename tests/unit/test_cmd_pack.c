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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
