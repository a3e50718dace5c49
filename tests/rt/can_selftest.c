/* Checks of the CAN master's pure parts: frame layouts, SDO abort texts,
 * EMCY and heartbeat wording, the CiA 402 state machine. No bus needed. */
#include <stdio.h>
#include <string.h>

#include "ncpar/can.h"

int selftest(void);

static int failures;

#define CHECK(cond)                                                           \
    do {                                                                      \
        if (!(cond)) {                                                        \
            fprintf(stderr, "selftest: %s:%d: %s\n", __FILE__, __LINE__, #cond); \
            failures++;                                                       \
        }                                                                     \
    } while (0)

static void sdo_frames(void)
{
    struct ncp_can_frame f;
    ncp_sdo_download_req(&f, 3, 0x6060, 0, 8, 1);
    CHECK(f.id == 0x603 && f.len == 8 && f.data[0] == 0x2F && f.data[1] == 0x60 &&
          f.data[2] == 0x60 && f.data[3] == 0 && f.data[4] == 8);
    ncp_sdo_download_req(&f, 3, 0x1017, 0, 50, 2);
    CHECK(f.data[0] == 0x2B && f.data[4] == 50 && f.data[5] == 0);
    ncp_sdo_download_req(&f, 3, 0x1600, 1, 0x60400010, 4);
    CHECK(f.data[0] == 0x23 && f.data[4] == 0x10 && f.data[7] == 0x60);
    ncp_sdo_upload_req(&f, 127, 0x1000, 0);
    CHECK(f.id == 0x67F && f.data[0] == 0x40);
    ncp_sdo_upload_resp(&f, 1, 0x6061, 0, 8, 1);
    CHECK(f.id == 0x581 && f.data[0] == 0x4F);
    ncp_sdo_abort_frame(&f, 0x581, 0x2000, 1, 0x06020000);
    CHECK(f.data[0] == 0x80 && f.data[4] == 0x00 && f.data[6] == 0x02 && f.data[7] == 0x06);
    CHECK(!strcmp(ncp_sdo_abort_text(0x06020000),
                  "object does not exist in the object dictionary"));
    CHECK(!strcmp(ncp_sdo_abort_text(0x06090030), "invalid value for parameter"));
    CHECK(!strcmp(ncp_sdo_abort_text(0x12345678), "unknown abort code"));
}

static void pdo_nmt_emcy(void)
{
    struct ncp_can_frame f;
    uint16_t w;
    int32_t p;
    ncp_rpdo1_frame(&f, 2, 0x000F, -123456);
    CHECK(f.id == 0x202 && f.len == 6);
    CHECK(ncp_rpdo1_decode(&f, &w, &p) == 0 && w == 0x000F && p == -123456);
    ncp_tpdo1_frame(&f, 2, 0x0237, 2147483647);
    CHECK(f.id == 0x182 && ncp_tpdo1_decode(&f, &w, &p) == 0 && w == 0x0237 &&
          p == 2147483647);
    f.len = 4;
    CHECK(ncp_tpdo1_decode(&f, &w, &p) == -1);
    ncp_nmt_frame(&f, NCP_NMT_START, 0);
    CHECK(f.id == 0 && f.len == 2 && f.data[0] == 1 && f.data[1] == 0);
    ncp_sync_frame(&f);
    CHECK(f.id == 0x080 && f.len == 0);
    struct ncp_emcy e = {.code = 0x8611, .reg = 0x21, .vendor = {0}}, e2;
    ncp_emcy_frame(&f, 5, &e);
    CHECK(f.id == 0x085 && ncp_emcy_decode(&f, &e2) == 0 && e2.code == 0x8611 &&
          e2.reg == 0x21);
    char buf[160];
    ncp_emcy_describe(&e2, buf, sizeof buf);
    CHECK(!strcmp(buf, "error code 0x8611 following error; error register 0x21: "
                       "generic, device profile"));
    e2.code = 0x4210;
    ncp_emcy_describe(&e2, buf, 20); /* truncation stays a string */
    CHECK(strlen(buf) == 19);
}

static void cia402(void)
{
    for (int s = NCP_402_NOT_READY; s <= NCP_402_FAULT; s++)
        CHECK((int)ncp_cia402_state(ncp_cia402_statusword((enum ncp_cia402_state)s)) == s);
    CHECK(ncp_cia402_state(0x0250) == NCP_402_SWITCH_ON_DISABLED);
    CHECK(ncp_cia402_state(0x1637) == NCP_402_OPERATION_ENABLED);
    CHECK(ncp_cia402_state(0x0008) == NCP_402_FAULT);
    CHECK(ncp_cia402_state(0x0017) == NCP_402_QUICK_STOP_ACTIVE);
    /* Walk a drive from Fault and from Switch on disabled to Operation enabled. */
    enum ncp_cia402_state starts[] = {NCP_402_FAULT, NCP_402_SWITCH_ON_DISABLED,
                                      NCP_402_QUICK_STOP_ACTIVE};
    for (size_t k = 0; k < sizeof starts / sizeof starts[0]; k++) {
        enum ncp_cia402_state s = starts[k];
        uint16_t prev = 0;
        int steps = 0;
        while (s != NCP_402_OPERATION_ENABLED && steps < 10) {
            uint16_t cw = ncp_cia402_step(s, prev);
            s = ncp_cia402_apply(s, cw, prev);
            prev = cw;
            steps++;
        }
        CHECK(s == NCP_402_OPERATION_ENABLED && steps <= 5);
    }
    CHECK(ncp_cia402_step(NCP_402_SWITCH_ON_DISABLED, 0) == 0x06);
    CHECK(ncp_cia402_step(NCP_402_READY_TO_SWITCH_ON, 0x06) == 0x07);
    CHECK(ncp_cia402_step(NCP_402_SWITCHED_ON, 0x07) == 0x0F);
    CHECK(ncp_cia402_step(NCP_402_FAULT, 0x00) == 0x80);
    CHECK(ncp_cia402_step(NCP_402_FAULT, 0x80) == 0x00);
    /* A held fault-reset bit must not reset twice: it acts on the edge. */
    CHECK(ncp_cia402_apply(NCP_402_FAULT, 0x80, 0x80) == NCP_402_FAULT);
    CHECK(ncp_cia402_apply(NCP_402_OPERATION_ENABLED, 0x02, 0x0F) == NCP_402_QUICK_STOP_ACTIVE);
}

static void monitor(void)
{
    struct ncp_co_node n[2];
    ncp_co_node_init(&n[0], 1);
    ncp_co_node_init(&n[1], 2);
    struct ncp_can_frame f;
    ncp_heartbeat_frame(&f, 2, NCP_NMT_OPERATIONAL);
    CHECK(ncp_co_track(n, 2, &f, 1000) == NCP_CO_HEARTBEAT && n[1].last_hb_ms == 1000);
    ncp_tpdo1_frame(&f, 1, 0x0237, 42);
    CHECK(ncp_co_track(n, 2, &f, 1001) == NCP_CO_TPDO && n[0].actual == 42);
    ncp_tpdo1_frame(&f, 9, 0x0237, 42);
    CHECK(ncp_co_track(n, 2, &f, 1001) == NCP_CO_NONE);
    struct ncp_diag d;
    CHECK(ncp_co_check_heartbeat(&n[1], 1100, 0, 200, &d) == NCP_OK);
    CHECK(ncp_co_check_heartbeat(&n[1], 1300, 0, 200, &d) != NCP_OK);
    CHECK(!strcmp(d.msg, "node 2: heartbeat (0x702) lost: last one 300 ms ago, timeout "
                         "200 ms (last state operational)"));
    CHECK(ncp_co_check_heartbeat(&n[0], 1300, 1000, 200, &d) != NCP_OK);
    uint32_t ids[10];
    CHECK(ncp_co_filter_ids(n, 2, ids, 10) == 10 && ids[0] == 0x581 && ids[2] == 0x281 &&
          ids[9] == 0x702);
}

int selftest(void)
{
    sdo_frames();
    pdo_nmt_emcy();
    cia402();
    monitor();
    printf("can selftest: %s\n", failures ? "FAILED" : "ok");
    return failures ? 1 : 0;
}
