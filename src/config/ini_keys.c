/* The machine INI's keys (ncpar/config.h): what the reader takes
 * and what ncpar.ini(5) says. A key the reader learns is a row here, or the
 * reader refuses it as unknown; tools/ini-man checks the rows against the
 * reader at build time. */
#include "ncpar/config.h"

#include <ctype.h>
#include <string.h>

#define REAL(s, k, lo, hi, unit, def, doc) { s, k, NCP_INI_REAL, lo, hi, unit, NULL, def, NULL, NULL, doc }
#define INT(s, k, lo, hi, unit, def, doc) { s, k, NCP_INI_INT, lo, hi, unit, NULL, def, NULL, NULL, doc }
#define CPU(s, k, doc) { s, k, NCP_INI_CPU, -1, 0, "", NULL, "-1", NULL, NULL, doc }
#define WORD(s, k, words, def, doc) { s, k, NCP_INI_WORD, 0, 0, "", words, def, NULL, NULL, doc }
#define TEXT(s, k, form, def, ex, doc) { s, k, NCP_INI_TEXT, 0, 0, "", form, def, ex, NULL, doc }

const struct ncp_ini_section ncp_ini_sections[] = {
    { "EMCMOT", "The position loop." },
    { "TRAJ", "The machine's axes and its path limits." },
    { "AXIS_<L>", "One section per axis of [TRAJ] COORDINATES (L: X Y Z A B C U V W). "
                  "MIN_LIMIT, MAX_LIMIT, MAX_VELOCITY, MAX_ACCELERATION and FERROR are "
                  "required: a machine never runs on a limit nobody wrote down. "
                  "Lengths in mm, A B C in degrees." },
    { "JOINT_<n>", "The limits of the servo of joint n (0 .. 8: the place of its letter in "
                   "COORDINATES), checked after the inverse kinematics; only with [KINS] "
                   "KINEMATICS other than trivkins. A key left out takes the axis's value." },
    { "KINS", "The kinematics, by LinuxCNC's module names, and their pivots under the "
              "names of its HAL pins (x-rot-point is X_ROT_POINT)." },
    { "PLANNER", "Look-ahead and acceleration profile." },
    { "RT", "The real-time threads (the thread map of the NCK) and the policy for a late or "
            "lost position-loop period." },
    { "SIM", "The simulated machine: its servo, switches, probe workpiece and inputs. "
             "The servo's drive saturates as an amplifier does, at 3 times each joint's "
             "MAX_VELOCITY and MAX_ACCELERATION, so any gain in range is safe: a loop "
             "that cannot follow is stopped by FERROR." },
    { "SPINDLE_0", "The simulated spindle." },
    { "EMCIO", "The tool changer (LinuxCNC's keys)." },
    { "CAN", "The socketcan backend: CiA 402 drives on a CAN interface." },
    { "LCM", "The service's messaging (cnc-run serve, cnc-ctl) and the distributed mode "
             "(cnc-run run --backend lcm, cnc-axis)." },
    { "INJECT", "Timing faults injected into the real position loop (tests and experiments)." },
    { "SCHED", "Priorities of the soft real-time tasks below the position loop." },
    { "RS274NGC", "The interpreter's keys and files of a LinuxCNC INI, so that one file "
                  "configures the machine and its interpreter (docs/remap.md); cnc-run parse "
                  "and check read the same keys with --ini INI." },
    { "DISPLAY", "LinuxCNC's display section: how far an operator may turn the overrides "
                 "(cnc-ctl override, the panel), and where user M codes are." },
    { "CHANNEL_<n>", "Not a machine INI's section: a channels INI (cnc-run serve --config "
                     "CELL.ini) holds only [CHANNEL_n] sections (n 0 .. 15), one per NC "
                     "channel, each naming its machine INI and what drives it, so that one "
                     "service runs channel 0 on the simulator and channel 1 on CAN drives or "
                     "on cnc-axis LLCs (docs/operator.md)." },
    { "HTTP", "The operator's panel in a browser (cnc-run serve --http): who may reach it "
              "besides its own origin and address (docs/panel-security.md)." },
};
const size_t ncp_ini_n_sections = sizeof ncp_ini_sections / sizeof ncp_ini_sections[0];

const struct ncp_ini_key ncp_ini_keys[] = {
    REAL("EMCMOT", "SERVO_PERIOD", 125000, 10000000, "ns", "1000000",
         "Period of the position loop."),
    WORD("EMCMOT", "BACKEND", "sim|socketcan|lcm", "sim",
         "What cnc-run run and serve drive when no --backend is given: the simulated "
         "machine, CiA 402 drives over [CAN] INTERFACE, or one cnc-axis per axis over LCM "
         "at [LCM] DP (docs/distributed.md). cnc-axis takes its own drive from its "
         "--backend, never from this key."),

    TEXT("TRAJ", "COORDINATES", "axis letters of XYZABCUVW, each once", "XYZ", "XYZ",
         "The machine's axes; each needs its [AXIS_L] section."),
    REAL("TRAJ", "MAX_LINEAR_VELOCITY", 1e-6, 1e6, "mm/s", "200",
         "Top speed along the path."),
    REAL("TRAJ", "PLANNING_PERIOD", 125000, 100000000, "ns", "SERVO_PERIOD",
         "Period of the rough interpolation, a whole multiple of SERVO_PERIOD; the position "
         "loop interpolates between its points."),
    REAL("TRAJ", "DEFAULT_LINEAR_ACCELERATION", 0, 1e8, "mm/s^2", "0",
         "Acceleration along the path; 0: the axes' limits."),
    REAL("TRAJ", "DEFAULT_LINEAR_VELOCITY", 1e-6, 1e6, "mm/s", "10", "Jog speed."),
    INT("TRAJ", "NO_FORCE_HOMING", 0, 1, "", "0",
        "1: programs, MDI and jogs may run before the axes are homed."),

    REAL("AXIS_<L>", "MIN_LIMIT", -1e6, 1e6, "mm", NULL, "Soft limit, below MAX_LIMIT."),
    REAL("AXIS_<L>", "MAX_LIMIT", -1e6, 1e6, "mm", NULL, "Soft limit."),
    REAL("AXIS_<L>", "MAX_VELOCITY", 1e-6, 1e6, "mm/s", NULL, "Velocity limit."),
    REAL("AXIS_<L>", "MAX_ACCELERATION", 1e-6, 1e8, "mm/s^2", NULL, "Acceleration limit."),
    REAL("AXIS_<L>", "MAX_JERK", 0, 1e12, "mm/s^3", "100000",
         "Jerk limit; required with [PLANNER] PROFILE = scurve."),
    REAL("AXIS_<L>", "FERROR", 1e-9, 1e6, "mm",
         NULL, "Following error at which the machine faults."),
    REAL("AXIS_<L>", "COUNTS_PER_MM", 1e-3, 1e9, "counts/mm", NULL,
         "socketcan backend: encoder counts of the axis's drive per mm."),
    INT("AXIS_<L>", "NODE_ID", 1, 127, "", NULL,
        "socketcan backend: the CANopen node-ID of the axis's drive."),
    { "AXIS_<L>", "WRAPPED_ROTARY", NCP_INI_INT, 0, 1, "", NULL, "0", NULL, "AXIS_A",
      "A, B and C only: 1, the axis turns without end (moves take the shorter way round, "
      "no soft limits)." },
    REAL("AXIS_<L>", "HOME", -1e6, 1e6, "mm", "0", "Where the axis goes once homed."),
    REAL("AXIS_<L>", "HOME_OFFSET", -1e6, 1e6, "mm", "0",
         "Position of the home switch once homed."),
    REAL("AXIS_<L>", "HOME_SEARCH_VEL", -1e6, 1e6, "mm/s", "0",
         "Signed speed of the search for the switch; 0: no switch, homed where it stands."),
    REAL("AXIS_<L>", "HOME_LATCH_VEL", -1e6, 1e6, "mm/s", "0",
         "Signed latch speed: the same sign latches moving onto the switch, the opposite "
         "moving off it."),
    REAL("AXIS_<L>", "HOME_FINAL_VEL", 0, 1e6, "mm/s", "0",
         "Speed of the move to HOME; 0: MAX_VELOCITY."),
    INT("AXIS_<L>", "HOME_SEQUENCE", -99, 99, "", NULL,
        "Homing order; negative: the group's final moves start together."),
    WORD("AXIS_<L>", "HOME_IGNORE_LIMITS", "0|1|NO|YES|FALSE|TRUE", "0",
         "The limit switch is the home switch."),
    WORD("AXIS_<L>", "HOME_USE_INDEX", "0|NO|FALSE", "0",
         "The simulated machine has no encoder index: only 0."),
    TEXT("AXIS_<L>", "HOME_METHOD", "nck, or drive:N with N a CiA 402 homing method, -128 to 127",
         "nck", "drive:35",
         "Who homes the axis. nck: the position loop, on the keys above. drive:N (socketcan "
         "backend): the axis's drive in its own homing mode (0x6060 = 6), method N (0x6098), "
         "speeds |HOME_SEARCH_VEL| and |HOME_LATCH_VEL| (0x6099), MAX_ACCELERATION (0x609A), "
         "its position at home HOME_OFFSET (0x607C); then the axis goes to HOME. "
         "cnc-drive-sim implements methods 3, 4, 19, 20 (home switch, with and without index "
         "pulse), 35 and 37 (the current position)."),

    REAL("JOINT_<n>", "MIN_LIMIT", -1e6, 1e6, "mm (deg)", "the axis's", "Joint limit."),
    REAL("JOINT_<n>", "MAX_LIMIT", -1e6, 1e6, "mm (deg)", "the axis's", "Joint limit."),
    REAL("JOINT_<n>", "MAX_VELOCITY", 1e-6, 1e6, "mm/s (deg/s)", "the axis's",
         "Joint velocity limit."),
    REAL("JOINT_<n>", "MAX_ACCELERATION", 1e-6, 1e8, "mm/s^2 (deg/s^2)", "the axis's",
         "Joint acceleration limit."),
    REAL("JOINT_<n>", "FERROR", 1e-9, 1e6, "mm (deg)", "the axis's",
         "Following error at which the machine faults."),

    WORD("KINS", "KINEMATICS", "trivkins|xyzac-trt|xyzbc-trt", "trivkins",
         "The transform (parameters after the name, as LinuxCNC writes them, are ignored); "
         "xyzac-trt and xyzbc-trt need those axes."),
    REAL("KINS", "X_ROT_POINT", -1e6, 1e6, "mm", "0", "Pivot of the rotary table."),
    REAL("KINS", "Y_ROT_POINT", -1e6, 1e6, "mm", "0", "Pivot of the rotary table."),
    REAL("KINS", "Z_ROT_POINT", -1e6, 1e6, "mm", "0", "Pivot of the rotary table."),
    REAL("KINS", "X_OFFSET", -1e6, 1e6, "mm", "0", "xyzbc-trt: offset of the B pivot."),
    REAL("KINS", "Y_OFFSET", -1e6, 1e6, "mm", "0", "xyzac-trt: offset of the A pivot."),
    REAL("KINS", "Z_OFFSET", -1e6, 1e6, "mm", "0", "Offset of the second pivot."),

    INT("PLANNER", "LOOKAHEAD", 2, 100000, "segments", "200", "Look-ahead window."),
    INT("PLANNER", "SETPOINT_RING", 4, 1048576, "planning periods", "1024",
        "Setpoints buffered before the position loop; must hold half a stop from "
        "MAX_LINEAR_VELOCITY."),
    WORD("PLANNER", "PROFILE", "trapezoid|scurve", "trapezoid",
         "scurve: jerk-limited ramps within each axis's MAX_JERK."),
    WORD("PLANNER", "NCK", "adcbi|adcai", "adcbi",
         "Acceleration before interpolation along the path, or after it per axis."),

    INT("RT", "POSITION_PRIORITY", 0, 99, "", "90",
        "Position loop: 0 SCHED_OTHER, 1..99 SCHED_FIFO."),
    CPU("RT", "POSITION_CPU", "Position loop's CPU; -1: the OS chooses."),
    INT("RT", "PLANNER_PRIORITY", 0, 99, "", "0", "Planner thread, as POSITION_PRIORITY."),
    CPU("RT", "PLANNER_CPU", "Planner thread's CPU."),
    INT("RT", "INTERP_PRIORITY", 0, 99, "", "0", "Interpreter threads, as POSITION_PRIORITY."),
    CPU("RT", "INTERP_CPU", "Interpreter threads' CPU."),
    WORD("RT", "MISS_POLICY", "hold|extrapolate|extrapolate2|timestamped", "hold",
         "The setpoint of a late or lost period."),
    WORD("RT", "SETPOINT_FRAMES", "shared|per-axis", "shared",
         "One frame for every axis, or one per axis (a miss or loss hits one axis)."),
    INT("RT", "MAX_CONSECUTIVE_MISSES", 0, 1000000, "periods", "0",
        "Misses in a row that stop the machine; 0: no limit."),
    REAL("RT", "MAX_MISS_RATIO", 0, 1, "", "0",
         "Misses per period over MISS_WINDOW that stop the machine; 0: no limit."),
    INT("RT", "MISS_WINDOW", 1, 100000, "periods", "1000", "Window of MAX_MISS_RATIO."),

    REAL("SIM", "KP", 0, 1e9, "", "40", "Servo PID: proportional gain."),
    REAL("SIM", "KI", 0, 1e9, "", "0", "Servo PID: integral gain."),
    REAL("SIM", "KD", 0, 1e9, "", "0.46", "Servo PID: derivative gain."),
    REAL("SIM", "FF1", 0, 1e9, "", "0.1", "Velocity feed-forward."),
    REAL("SIM", "FF2", 0, 1e9, "", "0.004", "Acceleration feed-forward."),
    REAL("SIM", "HOME_SWITCH_<L>", -1e6, 1e6, "mm", "HOME_OFFSET",
         "Where axis L's simulated home switch is, in the machine's own coordinates."),
    REAL("SIM", "PROBE_PLANE_Z", -1e6, 1e6, "mm", NULL,
         "The probe touches below this plane (machine coordinates)."),
    TEXT("SIM", "PROBE_BOX", "xmin ymin zmin xmax ymax zmax, mm, each min below its max",
         NULL, "0 0 -10 100 100 0", "The probe touches inside this box."),
    REAL("SIM", "AUTO_RESUME_S", -1, 1e6, "s", "0",
         "How long cnc-run run's program pauses last; negative: until SIGUSR1."),
    INT("SIM", "DIGITAL_IN_<n>", 0, 1, "", "0", "cnc-run run's digital input n (0..63)."),
    REAL("SIM", "ANALOG_IN_<n>", -1e9, 1e9, "", "0", "cnc-run run's analog input n (0..15)."),

    REAL("SPINDLE_0", "MAX_RPM", 0, 1e6, "rpm", "0", "S above it runs at it; 0: no cap."),
    REAL("SPINDLE_0", "MAX_ACCELERATION", 0, 1e9, "rpm/s", "0", "0: at speed at once."),
    REAL("SPINDLE_0", "ORIENT_RPM", 1e-3, 1e5, "rpm", "60", "M19's top speed."),
    REAL("SPINDLE_0", "AT_SPEED_TOLERANCE", 1e-6, 1, "", "0.01",
         "Fraction of S within which the spindle is at speed."),

    INT("EMCIO", "TOOL_CHANGE_QUILL_UP", 0, 1, "", "0",
        "1: Z goes to machine 0 before a tool change."),
    TEXT("EMCIO", "TOOL_CHANGE_POSITION", "X Y Z, machine coordinates, mm", NULL, "0 0 0",
         "Where a tool change happens; not given: where the machine is."),
    TEXT("EMCIO", "TOOL_TABLE", "a path, relative to the INI's folder", NULL, "tool.tbl",
         "The tool table (LinuxCNC's format) of cnc-run run and serve when --tool-table is "
         "not given; under serve, G10 L1, L10 and L11 write their changes back to it "
         "(temporary file, fsync, rename), its comments and other lines kept."),

    TEXT("RS274NGC", "PARAMETER_FILE", "a path, relative to the INI's folder", NULL,
         "linuxcnc.var",
         "LinuxCNC's parameter file: cnc-run serve reads it at start (missing: G54, all "
         "offsets 0) and writes it whole (temporary file, fsync, rename) after each program, "
         "MDI line or stop that changed a persistent parameter, and at shutdown (cnc-run run: "
         "read at start, written at its end): G28 and G30 "
         "positions (#5161-#5169, #5181-#5189), G92 (#5210-#5219), the coordinate system "
         "(#5220) and G54..G59.3 (#5221-#5390, R included). Values in the interpreter's "
         "user unit (inch), as the tool table's. Not given: nothing persists."),

    REAL("DISPLAY", "MAX_FEED_OVERRIDE", 1.0, 2.0, "", "1.0",
         "Highest feed override, a ratio (1.2 = 120 %). Motion is planned at this override "
         "and slowed in time below it, so no axis exceeds its limits at any override; above "
         "1.0, moves that the limits cap run that much slower at 100 %."),
    REAL("DISPLAY", "MAX_SPINDLE_OVERRIDE", 0.0, 2.0, "", "2.0",
         "Highest spindle override, a ratio (the spindle stays under [SPINDLE_0] MAX_RPM)."),
    REAL("DISPLAY", "MIN_SPINDLE_OVERRIDE", 0.0, 2.0, "", "0.0",
         "Lowest spindle override, a ratio, not above MAX_SPINDLE_OVERRIDE."),
    TEXT("DISPLAY", "HISTORY_FILE", "a path, relative to the INI's folder", NULL,
         "history.jsonl",
         "cnc-run serve's job history: one JSON line appended (whole, then fsync) at the "
         "end of each program run: start, end, program, result (done, error, stopped, "
         "estop, fault), reason, the program's SHA-256, program time, largest following "
         "error and the estimate made at its load; cnc-ctl history shows it. Not given: "
         "$XDG_DATA_HOME/ncpar/history.jsonl (~/.local/share/ncpar/history.jsonl); NONE: "
         "no history."),
    TEXT("EMCIO", "CYCLE_TIME", "LinuxCNC's", NULL, "0.1", "Taken and ignored."),
    TEXT("EMCIO", "EMCIO", "LinuxCNC's", NULL, "io", "Taken and ignored."),
    TEXT("EMCIO", "RANDOM_TOOLCHANGER", "LinuxCNC's", NULL, "0", "Taken and ignored."),
    TEXT("EMCIO", "TOOL_CHANGE_WITH_SPINDLE_ON", "LinuxCNC's", NULL, "0", "Taken and ignored."),
    TEXT("EMCIO", "TOOL_CHANGE_AT_G30", "LinuxCNC's", NULL, "0", "Taken and ignored."),

    TEXT("CAN", "INTERFACE", "an interface name, 1 to 15 characters without blanks, / or :",
         NULL, "can0", "The CAN interface (cnc-run run --backend socketcan without :IFACE)."),
    INT("CAN", "HEARTBEAT_PERIOD_MS", 1, 65535, "ms", "50", "The drives' heartbeat (0x1017)."),
    INT("CAN", "HEARTBEAT_TIMEOUT_MS", 1, 600000, "ms", "500",
        "A drive whose heartbeat is this late is lost."),
    INT("CAN", "SDO_TIMEOUT_MS", 1, 600000, "ms", "200", "Deadline of a start-up SDO answer."),
    INT("CAN", "HEARTBEAT_CONSUMER_MS", 1, 65535, "ms", "150",
        "The drives stop when our heartbeat is this late (0x1016)."),
    INT("CAN", "RPDO_TIMEOUT_MS", 0, 65535, "ms", "100",
        "... or RPDO1 (0x1400:05); 0: off."),
    INT("CAN", "MASTER_NODE", 0, 127, "", "127",
        "Node-ID of our heartbeat; 0: the drives do not guard the master."),
    INT("CAN", "ABORT_CONNECTION_OPTION", 0, 3, "", "3", "CiA 402 object 0x6007."),
    INT("CAN", "FAULT_REACTION_OPTION", 0, 4, "", "2", "CiA 402 object 0x605E."),

    TEXT("LCM", "URL", "an LCM URL, up to 255 characters", NULL,
         "udpm://239.255.76.67:7667?ttl=0",
         "Not given: $LCM_DEFAULT_URL, else LCM's default."),
    TEXT("LCM", "CHANNEL_PREFIX", "letters, digits and _, up to 31", "NCP_", "NCP_",
         "Prefix of the channels CMD, ACK, STATUS and EVENT."),
    REAL("LCM", "STATUS_HZ", 0, 1000, "Hz", "50",
         "Status rate; 0: only at changes and after each command."),
    WORD("LCM", "CLOCK", "monotonic|probe|ptp", "monotonic",
         "Distributed mode's time base: one host, estimated from round trips, or "
         "CLOCK_REALTIME kept by ptp4l/phc2sys."),
    INT("LCM", "DP", 1, 5, "", "5", "Distribution point."),
    INT("LCM", "MAX_LOST_PERIODS", 1, 100000, "periods", "20",
        "Messages missing in a row before a controlled stop."),
    INT("LCM", "HEARTBEAT_PERIOD_MS", 1, 10000, "ms", "20", "Heartbeat period."),
    INT("LCM", "HEARTBEAT_TIMEOUT_MS", 2, 60000, "ms", "200",
        "A peer silent this long is lost; above HEARTBEAT_PERIOD_MS."),
    INT("LCM", "AXIS_WAIT_MS", 1, 600000, "ms", "5000",
        "How long the HLC waits for the axes' advertisements."),
    INT("LCM", "CLOCK_TOLERANCE_US", 1, 10000000, "us", "1000",
        "Under monotonic and ptp, an LLC whose probes find the clocks further apart stops."),
    REAL("LCM", "INJECT_LOSS", 0, 1, "", "0", "Fraction of received messages dropped (tests)."),
    INT("LCM", "INJECT_DELAY_US", 0, 1000000, "us", "0",
        "Every received message held back this long (tests)."),
    INT("LCM", "INJECT_SEED", 0, 2147483647, "", "1", "Seed of INJECT_LOSS."),
    TEXT("LCM", "KEY_FILE", "a path, up to 511 characters", NULL, "/etc/ncpar/lcm.key",
         "The shared key that seals every LCM message (32 random bytes or 64 hex digits, "
         "mode 0600). Not given: --key-file, else $XDG_CONFIG_HOME/ncpar/lcm.key, else "
         "~/.config/ncpar/lcm.key. cnc-run serve makes it when it does not exist."),
    TEXT("LCM", "INTERFACE", "a network interface's name, or empty for any", "lo", "eth0",
         "The multicast group is joined on this interface only, and the socket bound to the "
         "group: datagrams sent to this host's own address or arriving elsewhere never "
         "reach the NCK."),
    INT("LCM", "STATUS_NEEDS_KEY", 0, 1, "", "0",
        "1: STATUS and EVENT are encrypted with the key; a display then needs the key too."),
    INT("LCM", "MAX_AGE_MS", 0, 3600000, "ms", "2000",
        "The distributed NCK drops a message sealed longer ago (or further ahead) than this: "
        "a recording played back moves nothing. 0: no limit."),

    TEXT("HTTP", "ALLOW_ORIGIN", "origins (http://host[:port]) separated by spaces or commas",
         NULL, "http://panel.example:8080",
         "Pages from these origins may use the panel as well as its own; any other Origin "
         "is refused (403), token or not."),
    TEXT("HTTP", "ALLOW_HOST", "host names or addresses, with or without a port, separated by "
         "spaces or commas", NULL, "cnc1.shop.example",
         "Host headers accepted besides the bound address and localhost; any other gets 421 "
         "(DNS rebinding). A panel bound to 0.0.0.0 lists the machine's own names here."),

    TEXT("RS274NGC", "REMAP", "CODE [modalgroup=N] [argspec=WORDS] [prolog=NAME] ngc=NAME "
         "[epilog=NAME], as LinuxCNC's", NULL, "M6 modalgroup=6 prolog=change_prolog ngc=change "
         "epilog=change_epilog",
         "The code runs the O-word subroutine NAME.ngc; given once per remapped code. "
         "stdglue's prologs and epilogs are built in; python= is refused."),
    TEXT("RS274NGC", "SUBROUTINE_PATH", "folders separated by ':', relative to the INI's folder",
         NULL, "subs:/usr/share/ncpar/subs",
         "Where o<name> call and the REMAP subs find name.ngc, after the current folder and "
         "--subroutine-path."),
    TEXT("RS274NGC", "USER_M_PATH", "folders separated by ':', relative to the INI's folder",
         NULL, "mcodes",
         "Where the executables M100 .. M199 are, after PROGRAM_PREFIX; each runs with P "
         "and Q as two arguments once the machine is at rest."),
    WORD("RS274NGC", "INI_VARS", "0|1|NO|YES|FALSE|TRUE|OFF|ON", "1",
         "The program reads the INI's keys as #<_ini[SECTION]KEY>."),
    WORD("RS274NGC", "OWORD_NARGS", "0|1|NO|YES|FALSE|TRUE|OFF|ON", "0",
         "A called subroutine has #<n_args>, the number of its arguments (read-only)."),
    WORD("RS274NGC", "DISABLE_FANUC_STYLE_SUB", "0|1|NO|YES|FALSE|TRUE|OFF|ON", "0",
         "M98, M99 and bare O-word lines (Fanuc-style subroutines) are refused."),
    REAL("RS274NGC", "ORIENT_OFFSET", -1e9, 1e9, "degrees", "0",
         "Added to the angle of M19 (its R word, 0 without one)."),
    TEXT("DISPLAY", "PROGRAM_PREFIX", "a folder, relative to the INI's folder", NULL,
         "nc_files", "The program folder (its first folder, if several): the panel lists, "
         "loads and stores uploads there. Also the first folder searched for the "
         "executables M100 .. M199."),

    TEXT("INJECT", "SPEC", "specs separated by commas, as cnc-run run --inject", NULL,
         "miss=0.01", "The faults."),
    INT("INJECT", "SEED", 0, 9007199254740992.0, "", "1", "Their seed."),

    WORD("SCHED", "STRATEGY", "static|dataflow|none", "none",
         "Rank the soft real-time tasks by their dependencies, by their rings' fill, or not."),
    INT("SCHED", "PERIOD_MS", 1, 1000, "ms", "10", "Period of the scheduler."),
    INT("SCHED", "PRIORITY_MIN", 1, 97, "", "1", "Lowest SCHED_FIFO priority of the band."),
    INT("SCHED", "TRACE_RINGS", 0, 1, "", "0", "1: the rings' fill levels in the trace."),

    TEXT("CHANNEL_<n>", "CONFIG", "a path, relative to the channels INI's folder", NULL,
         "mill.ini", "The machine INI of channel n; required."),
    TEXT("CHANNEL_<n>", "BACKEND", "sim, socketcan, socketcan:IFACE or lcm", NULL,
         "socketcan:can1",
         "What drives channel n's axes, over its machine INI's [EMCMOT] BACKEND (left out: "
         "that one): the simulated machine, CiA 402 drives ([AXIS_L] NODE_ID of every axis) "
         "on IFACE or the machine's [CAN] INTERFACE, or one cnc-axis per axis over the "
         "machine's [LCM] URL. No two channels share a CAN interface (each master sends its "
         "own SYNC) or an LCM URL (the LLCs hear one HLC)."),
    INT("CHANNEL_<n>", "DP", 1, 5, "", NULL,
        "Distribution point of a BACKEND = lcm channel, over its machine INI's [LCM] DP "
        "(left out: that one)."),
};
const size_t ncp_ini_n_keys = sizeof ncp_ini_keys / sizeof ncp_ini_keys[0];

/* name against pattern: any case, '-' as '_', <L> an axis letter, <n> digits */
static int match(const char *pat, const char *name)
{
    while (*pat) {
        if (!strncmp(pat, "<L>", 3)) {
            if (!*name || !strchr("XYZABCUVW", toupper((unsigned char)*name)))
                return 0;
            name++;
            pat += 3;
        } else if (!strncmp(pat, "<n>", 3)) {
            size_t d = strspn(name, "0123456789");
            if (!d)
                return 0;
            name += d;
            pat += 3;
        } else {
            int a = toupper((unsigned char)*pat), b = toupper((unsigned char)*name);
            if (a != (b == '-' ? '_' : b))
                return 0;
            pat++;
            name++;
        }
    }
    return !*name;
}

const struct ncp_ini_key *ncp_ini_key_find(const char *sec, const char *key)
{
    for (size_t i = 0; i < ncp_ini_n_keys; i++)
        if (match(ncp_ini_keys[i].section, sec) && match(ncp_ini_keys[i].key, key))
            return &ncp_ini_keys[i];
    return NULL;
}
