/* G and M codes by name. The analyzer keeps a G code as its value times ten
 * (G38.2 is 382, G5.3 is 53, G53 is 530: see struct ncp_words), so that every
 * code, dotted or not, is one small integer; M codes are kept whole (M6 is 6).
 * NCP_G5_3 reads "G5.3". Only the codes the analyzer knows are listed: the
 * G table in words.c and the M groups beside it name every one of them. */
#ifndef NCP_ANALYZER_CODES_H
#define NCP_ANALYZER_CODES_H

enum ncp_gcode {
    NCP_G0 = 0, NCP_G1 = 10, NCP_G2 = 20, NCP_G3 = 30, NCP_G4 = 40, NCP_G5 = 50,
    NCP_G5_1 = 51, NCP_G5_2 = 52, NCP_G5_3 = 53, NCP_G7 = 70, NCP_G8 = 80, NCP_G10 = 100,
    NCP_G17 = 170, NCP_G17_1 = 171, NCP_G18 = 180, NCP_G18_1 = 181, NCP_G19 = 190,
    NCP_G19_1 = 191, NCP_G20 = 200, NCP_G21 = 210, NCP_G28 = 280, NCP_G28_1 = 281,
    NCP_G30 = 300, NCP_G30_1 = 301, NCP_G33 = 330, NCP_G33_1 = 331, NCP_G38_2 = 382,
    NCP_G38_3 = 383, NCP_G38_4 = 384, NCP_G38_5 = 385, NCP_G40 = 400, NCP_G41 = 410,
    NCP_G41_1 = 411, NCP_G42 = 420, NCP_G42_1 = 421, NCP_G43 = 430, NCP_G43_1 = 431,
    NCP_G43_2 = 432, NCP_G49 = 490, NCP_G52 = 520, NCP_G53 = 530, NCP_G54 = 540,
    NCP_G55 = 550, NCP_G56 = 560, NCP_G57 = 570, NCP_G58 = 580, NCP_G59 = 590,
    NCP_G59_1 = 591, NCP_G59_2 = 592, NCP_G59_3 = 593, NCP_G61 = 610, NCP_G61_1 = 611,
    NCP_G64 = 640, NCP_G70 = 700, NCP_G71 = 710, NCP_G71_1 = 711, NCP_G71_2 = 712,
    NCP_G72 = 720, NCP_G72_1 = 721, NCP_G72_2 = 722, NCP_G73 = 730, NCP_G74 = 740,
    NCP_G76 = 760, NCP_G80 = 800, NCP_G81 = 810, NCP_G82 = 820, NCP_G83 = 830,
    NCP_G84 = 840, NCP_G85 = 850, NCP_G86 = 860, NCP_G87 = 870, NCP_G88 = 880,
    NCP_G89 = 890, NCP_G90 = 900, NCP_G90_1 = 901, NCP_G91 = 910, NCP_G91_1 = 911,
    NCP_G92 = 920, NCP_G92_1 = 921, NCP_G92_2 = 922, NCP_G92_3 = 923, NCP_G93 = 930,
    NCP_G94 = 940, NCP_G95 = 950, NCP_G96 = 960, NCP_G97 = 970, NCP_G98 = 980,
    NCP_G99 = 990,
};

enum ncp_mcode {
    NCP_M0 = 0, NCP_M1 = 1, NCP_M2 = 2, NCP_M3 = 3, NCP_M4 = 4, NCP_M5 = 5, NCP_M6 = 6,
    NCP_M7 = 7, NCP_M8 = 8, NCP_M9 = 9, NCP_M19 = 19, NCP_M30 = 30, NCP_M48 = 48,
    NCP_M49 = 49, NCP_M50 = 50, NCP_M51 = 51, NCP_M52 = 52, NCP_M53 = 53, NCP_M60 = 60,
    NCP_M61 = 61, NCP_M62 = 62, NCP_M63 = 63, NCP_M64 = 64, NCP_M65 = 65, NCP_M66 = 66,
    NCP_M67 = 67, NCP_M68 = 68, NCP_M70 = 70, NCP_M71 = 71, NCP_M72 = 72, NCP_M73 = 73,
    NCP_M98 = 98, NCP_M99 = 99,
    /* rs274's group 10: user M codes, the machine's programs M100..M199 */
    NCP_M100 = 100, NCP_M199 = 199,
};

#endif
