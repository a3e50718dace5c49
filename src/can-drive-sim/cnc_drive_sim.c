/* cnc-drive-sim IFACE --node N [switches]: a simulated CiA 402 servo drive
 * on a (v)CAN interface, with switches that inject the faults a real drive
 * can show, so the master's reactions can be tested without hardware. */
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "drive.h"
#include "ncp_version.h"
#include "ncpar/clock.h"
#include "ncpar/num.h"

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
    (void)sig;
    stop = 1;
}

static void usage(FILE *f)
{
    fputs("usage: cnc-drive-sim IFACE --node N [options]\n"
          "  --fault-at-start          start in Fault (needs a fault reset)\n"
          "  --fault-after K           enter Fault after K SYNCs in Operation enabled\n"
          "  --emcy-after K            send EMCY 0x8611 (following error) and enter Fault\n"
          "  --heartbeat-stop-after K  stop producing heartbeats\n"
          "  --count-from-motion       count those K SYNCs from the first target that\n"
          "                            differs from the one at enabling, not from enabling\n"
          "  --slow-sdo MS             answer every SDO MS milliseconds late\n"
          "  --sdo-abort INDEX         abort every SDO access to object INDEX (0x6060...)\n"
          "  --drop-every K            drop every K-th TPDO\n"
          "  --max-step COUNTS         plant slew limit per SYNC (default 1000000)\n"
          "  --config INI --axis X|Y|Z the servo plant of cnc-run's sim backend for that\n"
          "                            axis ([SIM] gains, COUNTS_PER_MM; period from 0x60C2)\n"
          "                            instead of the slew-limited plant\n"
          "  --sync-loss-ms MS         no SYNC for MS ms while enabled: EMCY 0x8700 and\n"
          "                            the stop of 0x6007 (default 100, 0 = never)\n"
          "  --home-switch COUNTS      home switch (0x60FD bit 2, in TPDO2 where the master\n"
          "                            maps it) pressed at and above this actual position\n"
          "  --index-pitch COUNTS      encoder index pulse at every multiple of COUNTS\n"
          "                            (homing methods 3 and 4)\n"
          "  --homing-error MS         the first homing ends MS ms in with a homing error\n"
          "                            (statusword bit 13), the axis stopped; later ones\n"
          "                            succeed\n"
          "  --homing-stall            the homing never sees the switch: it searches on,\n"
          "                            never attained\n"
          "  --verbose                 log state changes on stderr\n"
          "Answers NMT, SDO (expedited), SYNC and RPDO1/TPDO1 (controlword+target,\n"
          "statusword+actual); heartbeat period from object 0x1017 (default 100 ms).\n"
          "Homing mode (0x6060 = 6, started by controlword bit 4): methods 35 and 37 home\n"
          "on the current position; 19 and 20 on the home switch's edge (moving negative\n"
          "from the pressed side, positive from the released side), 3 and 4 on the first\n"
          "index pulse past it; speeds 0x6099:01/02, acceleration 0x609A, and at home the\n"
          "position becomes the home offset 0x607C.\n"
          "Guards the master: its heartbeat (consumer 0x1016:01), SYNC and RPDO1\n"
          "(deadline 0x1400:05); when one stops while enabled the drive sends EMCY\n"
          "(0x8130, 0x8700, 0x8250) and stops as 0x6007 and 0x605E say.\n",
          f);
}

static long num(const char *s, const char *opt, long lo, long hi)
{
    char why[160];
    long v;
    if (ncp_num_long(s, 0, lo, hi, &v) == 0)
        return v;
    ncp_num_why(why, sizeof why, opt, s, (double)lo, (double)hi);
    fprintf(stderr, "cnc-drive-sim: %s\n", why);
    exit(1);
}

static const char *parse(int argc, char **argv, struct drive_opts *o)
{
    static const struct option lo[] = {
        {"node", required_argument, 0, 'n'},         {"fault-at-start", no_argument, 0, 'F'},
        {"fault-after", required_argument, 0, 'f'},  {"emcy-after", required_argument, 0, 'e'},
        {"heartbeat-stop-after", required_argument, 0, 'H'},
        {"slow-sdo", required_argument, 0, 's'},     {"sdo-abort", required_argument, 0, 'a'},
        {"drop-every", required_argument, 0, 'd'},   {"max-step", required_argument, 0, 'm'},
        {"verbose", no_argument, 0, 'v'},            {"help", no_argument, 0, 'h'},
        {"config", required_argument, 0, 'c'},       {"axis", required_argument, 0, 'x'},
        {"sync-loss-ms", required_argument, 0, 'L'}, {"count-from-motion", no_argument, 0, 'M'},
        {"home-switch", required_argument, 0, 'S'},  {"index-pitch", required_argument, 0, 'I'},
        {"homing-error", required_argument, 0, 'E'}, {"homing-stall", no_argument, 0, 'T'},
        {0, 0, 0, 0}};
    *o = (struct drive_opts){.node = 0, .fault_after = -1, .emcy_after = -1,
                             .hb_stop_after = -1, .abort_index = -1, .max_step = 1000000,
                             .axis = -1, .sync_loss_ms = 100};
    int c;
    while ((c = getopt_long(argc, argv, "n:v", lo, NULL)) != -1) {
        switch (c) {
        case 'n': o->node = (uint8_t)num(optarg, "--node", 1, NCP_CAN_NODE_MAX); break;
        case 'F': o->fault_at_start = 1; break;
        case 'f': o->fault_after = num(optarg, "--fault-after", 1, 1L << 30); break;
        case 'e': o->emcy_after = num(optarg, "--emcy-after", 1, 1L << 30); break;
        case 'H': o->hb_stop_after = num(optarg, "--heartbeat-stop-after", 1, 1L << 30); break;
        case 's': o->slow_sdo_ms = (int)num(optarg, "--slow-sdo", 0, 60000); break;
        case 'a': o->abort_index = (int)num(optarg, "--sdo-abort", 0, 0xFFFF); break;
        case 'd': o->drop_every = num(optarg, "--drop-every", 1, 1L << 30); break;
        case 'm': o->max_step = (int32_t)num(optarg, "--max-step", 1, 1L << 30); break;
        case 'v': o->verbose = 1; break;
        case 'M': o->count_from_motion = 1; break;
        case 'L': o->sync_loss_ms = num(optarg, "--sync-loss-ms", 0, 600000); break;
        case 'c': o->config = optarg; break;
        case 'S':
            o->have_home_switch = 1;
            o->home_switch = (int32_t)num(optarg, "--home-switch", -(1L << 30), 1L << 30);
            break;
        case 'E': o->homing_error_ms = num(optarg, "--homing-error", 1, 600000); break;
        case 'T': o->homing_stall = 1; break;
        case 'I': o->index_pitch = (int32_t)num(optarg, "--index-pitch", 1, 1L << 30); break;
        case 'x':
            if (!optarg[0] || optarg[1] || !strchr("XYZxyz", optarg[0])) {
                fprintf(stderr, "cnc-drive-sim: --axis is X, Y or Z\n");
                exit(1);
            }
            o->axis = (int)(strchr("XYZ", optarg[0] & ~0x20) - "XYZ");
            break;
        case 'h': usage(stdout); exit(0);
        default: usage(stderr); exit(1);
        }
    }
    if (optind != argc - 1 || o->node == 0) {
        usage(stderr);
        exit(1);
    }
    return argv[optind];
}

int main(int argc, char **argv)
{
    static struct drive dv;
    if (argc == 2 && !strcmp(argv[1], "--version")) {
        printf("cnc-drive-sim (ncpar) %s\n", NCP_VERSION);
        return 0;
    }
    const char *ifname = parse(argc, argv, &dv.o);
    if (drive_servo_load(&dv))
        return 1;
    struct ncp_diag d;
    if (ncp_can_open(&dv.bus, ifname, &d) != NCP_OK) {
        fprintf(stderr, "cnc-drive-sim: %s\n", d.msg);
        return 1;
    }
    uint8_t n = dv.o.node;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    drive_boot(&dv);
    long long next_hb = ncp_mono_ms();
    uint32_t ids[6], listening[6];
    size_t n_listening = 0;
    int rc = 0;
    while (!stop) {
        /* the master's heartbeat joins the filter once 0x1016 names it */
        size_t n_ids = drive_listen_ids(&dv, ids);
        if (n_ids != n_listening || memcmp(ids, listening, n_ids * sizeof ids[0]) != 0) {
            if (ncp_can_filter(&dv.bus, ids, n_ids, &d) != NCP_OK) {
                fprintf(stderr, "cnc-drive-sim: %s\n", d.msg);
                rc = 1;
                break;
            }
            memcpy(listening, ids, n_ids * sizeof ids[0]);
            n_listening = n_ids;
        }
        long long t = ncp_mono_ms();
        if (drive_guard_tick(&dv, t) < 0) {
            rc = 1;
            break;
        }
        uint32_t period = od_get(&dv.od, 0x1017, 0);
        if (period > 0 && t >= next_hb) {
            if (drive_send_heartbeat(&dv) < 0)
                break;
            next_hb = t + period;
        }
        int wait = period > 0 ? (int)(next_hb - t) : 100;
        int guard = drive_guard_wait_ms(&dv, t);
        if (guard < wait)
            wait = guard;
        struct ncp_can_frame f;
        int r = ncp_can_recv(&dv.bus, &f, wait > 100 ? 100 : (wait < 0 ? 0 : wait), &d);
        if (r < 0) {
            fprintf(stderr, "cnc-drive-sim node %u: %s\n", n, d.msg);
            rc = 1;
            break;
        }
        if (r > 0 && drive_on_frame(&dv, &f, ncp_mono_ms()) < 0) {
            rc = 1;
            break;
        }
    }
    ncp_can_close(&dv.bus);
    return rc;
}
