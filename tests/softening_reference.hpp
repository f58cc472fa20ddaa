// Tests: the normalised bilinear softening curve of SPEC §4 in closed form —
// stress ratio against total displacement ratio through (1, 1), (a1, b1), (a2, 0).
#pragma once

inline double softening_reference(double x, double a1, double b1, double a2) {
    if (x <= 1) return x;
    if (x <= a1) return 1 + (b1 - 1) * (x - 1) / (a1 - 1);
    if (x <= a2) return b1 * (a2 - x) / (a2 - a1);
    return 0;
}
