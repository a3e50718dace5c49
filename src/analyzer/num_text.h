/* Numbers in the files an operator keeps (parameter file, tool table):
 * LinuxCNC's six decimals whenever they give the value back to 1e-12 (of
 * an inch: a femtometre's scale, far below any machine's resolution), else
 * as many as do; an offset measured in mm (0.3937007874016 in for 10 mm)
 * keeps its digits, and the last bit of a unit conversion makes no
 * "0.500000000000003". */
#ifndef NCP_ANALYZER_NUM_TEXT_H
#define NCP_ANALYZER_NUM_TEXT_H

#include <stddef.h>

/* plus: a '+' before positive values (the tool table's offsets). Returns
 * the characters written (out must hold 40). */
int ncp_num_text(char *out, size_t len, double v, int plus);

#endif
