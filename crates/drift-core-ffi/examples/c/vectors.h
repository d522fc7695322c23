/* The shared test vectors as C data (vectors_to_c.py writes vectors.c from testdata/vectors.json). */
#ifndef VECTORS_H
#define VECTORS_H

#include <stddef.h>
#include <stdint.h>

struct vector_model {
    const char *name;
    const uint8_t *image;
    size_t len;
};

/* One activation: floats are IEEE-754 bit patterns, as in the JSON file. */
struct vector_case {
    const char *name;
    size_t model;               /* index into vector_models */
    int powered_on;             /* 0: samples arrive without a power-on */
    uint32_t switch_on_raw[3];
    int has_previous;           /* 1: power_on_after with `previous` */
    uint32_t previous[6];       /* per axis: ambient °C, switch-off °C */
    int power_on_fails;
    size_t count;
    const uint32_t *samples;    /* count × [ms, rate x y z, temperature x y z] */
    const uint32_t *expected;   /* count × [corrected x y z, bias x y z, flags x y z] */
    const uint32_t *aux;        /* count × 4, or NULL: correct without auxiliary inputs */
};

extern const struct vector_model vector_models[];
extern const struct vector_case vector_cases[];
extern const size_t vector_case_count;
extern const size_t vector_cases_skipped;

#endif
