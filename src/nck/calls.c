/* How the NCK takes each canonical call: as motion, as state of the canon
 * map, as a machine function (aux.c), as text for the operator, or refused
 * before anything moves. Nothing the interpreter says is dropped silently:
 * docs/operator.md's table of calls is this file in prose. */
#include "nck_int.h"

#include <string.h>

/* RAW_TEXT carries the calls rs274 prints that have no kind of their own. */
static int raw_class(const char *text)
{
    static const struct { const char *prefix; int cls; } known[] = {
        { "FINISH()", NCK_CALL_STATE },                  /* the program's end */
        { "SPINDLE.0.WAIT_ORIENT_COMPLETE", NCK_CALL_AUX },/* M19 Q: the orient waits anyway */
        { "SET_TOOL_TABLE_ENTRY", NCK_CALL_STATE },      /* G10 L1/L10/L11: the interpreter's table */
        { "RELOAD_TOOLDATA()", NCK_CALL_STATE },
    };
    for (size_t k = 0; text && k < sizeof known / sizeof known[0]; k++)
        if (!strncmp(text, known[k].prefix, strlen(known[k].prefix)))
            return known[k].cls;
    return NCK_CALL_REFUSED;
}

int nck_call_class(const struct ncp_canon *op, const char *text)
{
    switch ((enum ncp_canon_kind)op->kind) {
    case NCP_C_STRAIGHT_TRAVERSE: case NCP_C_STRAIGHT_FEED: case NCP_C_ARC_FEED:
    case NCP_C_DWELL: case NCP_C_NURBS_FEED: case NCP_C_NURBS_POINTS: case NCP_C_RIGID_TAP:
    case NCP_C_STRAIGHT_PROBE:   /* against [SIM]'s workpiece; a queue buster (job.c) */
        return NCK_CALL_MOTION;
    case NCP_C_USE_LENGTH_UNITS: case NCP_C_SET_G5X_OFFSET: case NCP_C_SET_G92_OFFSET:
    case NCP_C_SET_XY_ROTATION: case NCP_C_SET_FEED_REFERENCE: case NCP_C_ON_RESET:
    case NCP_C_SET_FEED_RATE: case NCP_C_SET_FEED_MODE: case NCP_C_SET_TRAVERSE_RATE:
    case NCP_C_SELECT_PLANE: case NCP_C_SET_MOTION_CONTROL_MODE:
    case NCP_C_SET_NAIVECAM_TOLERANCE: case NCP_C_SET_SPINDLE_MODE:
    case NCP_C_USE_TOOL_LENGTH_OFFSET: case NCP_C_SET_CUTTER_RADIUS_COMPENSATION:
    case NCP_C_START_CUTTER_RADIUS_COMPENSATION: case NCP_C_STOP_CUTTER_RADIUS_COMPENSATION:
    case NCP_C_START_SPEED_FEED_SYNCH: case NCP_C_STOP_SPEED_FEED_SYNCH:
    case NCP_C_PROGRAM_END: case NCP_C_START_CHANGE:
        return NCK_CALL_STATE;
    case NCP_C_SET_SPINDLE_SPEED: case NCP_C_START_SPINDLE_CLOCKWISE:
    case NCP_C_START_SPINDLE_COUNTERCLOCKWISE: case NCP_C_STOP_SPINDLE_TURNING:
    case NCP_C_ORIENT_SPINDLE: case NCP_C_FLOOD_ON: case NCP_C_FLOOD_OFF: case NCP_C_MIST_ON:
    case NCP_C_MIST_OFF: case NCP_C_SELECT_TOOL: case NCP_C_CHANGE_TOOL:
    case NCP_C_CHANGE_TOOL_NUMBER: case NCP_C_ENABLE_FEED_OVERRIDE:
    case NCP_C_DISABLE_FEED_OVERRIDE: case NCP_C_ENABLE_SPEED_OVERRIDE:
    case NCP_C_DISABLE_SPEED_OVERRIDE: case NCP_C_ENABLE_FEED_HOLD: case NCP_C_DISABLE_FEED_HOLD:
    case NCP_C_ENABLE_ADAPTIVE_FEED: case NCP_C_DISABLE_ADAPTIVE_FEED:
    case NCP_C_PROGRAM_STOP: case NCP_C_OPTIONAL_PROGRAM_STOP: case NCP_C_PALLET_SHUTTLE:
    case NCP_C_SET_AUX_OUTPUT_BIT: case NCP_C_CLEAR_AUX_OUTPUT_BIT:
    case NCP_C_SET_MOTION_OUTPUT_BIT: case NCP_C_CLEAR_MOTION_OUTPUT_BIT:
    case NCP_C_SET_AUX_OUTPUT_VALUE: case NCP_C_SET_MOTION_OUTPUT_VALUE: case NCP_C_WAIT_INPUT:
    case NCP_C_USER_M:           /* the machine at rest, its program runs (user_m.c) */
        return NCK_CALL_AUX;
    case NCP_C_COMMENT: case NCP_C_MESSAGE: case NCP_C_LOGOPEN: case NCP_C_LOGAPPEND:
    case NCP_C_LOGCLOSE: case NCP_C_LOG: case NCP_C_PRINT:
    /* the probe move itself arms the simulated probe */
    case NCP_C_TURN_PROBE_ON: case NCP_C_TURN_PROBE_OFF:
        return NCK_CALL_INFO;
    case NCP_C_RAW_TEXT:
        return raw_class(text);
    case NCP_C_SPINDLE_RETRACT_TRAVERSE: case NCP_C_ARC_REQUEST:
    case NCP_C_NONE: case NCP_C__COUNT:
        break;
    }
    return NCK_CALL_REFUSED;
}

/* The message of a refused call (text: RAW_TEXT's). */
const char *nck_call_what(int kind)
{
    switch (kind) {
    case NCP_C_SPINDLE_RETRACT_TRAVERSE:
        return "SPINDLE_RETRACT_TRAVERSE: this machine has no spindle retract";
    default:
        return "a canonical call this machine cannot act on";
    }
}
