/* Replays the shared test vectors through the C interface (libdrift_core_ffi.a, gyrodrift.h) on
 * the Cortex-M4F and compares every output with the host's, bit for bit. Exit status 0 only if
 * all agree. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gyrodrift.h"
#include "vectors.h"

extern void initialise_monitor_handles(void);

/* One unit's context, zeroed in .bss: the C side owns it, gyrodrift_init fills it. */
static gyrodrift_context context;

static float from_bits(uint32_t bits) {
    float value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

static uint32_t to_bits(float value) {
    uint32_t bits;
    memcpy(&bits, &value, sizeof bits);
    return bits;
}

/* A NaN matches any NaN (payloads are not portable); everything else bit for bit. */
static int same(uint32_t expected, uint32_t got) {
    return expected == got || (isnan(from_bits(expected)) && isnan(from_bits(got)));
}

/* Runs one case on a freshly initialised context; returns the outputs that differ. */
static size_t run(const struct vector_case *c) {
    const struct vector_model *m = &vector_models[c->model];
    gyrodrift_status status = gyrodrift_init(&context, m->image, m->len);
    if (status != GYRODRIFT_STATUS_OK) {
        printf("%s: gyrodrift_init failed (%d)\n", c->name, (int)status);
        return 1;
    }
    gyrodrift_previous previous[GYRODRIFT_AXES];
    if (c->powered_on) {
        float raw[GYRODRIFT_AXES];
        for (int axis = 0; axis < GYRODRIFT_AXES; axis++) {
            raw[axis] = from_bits(c->switch_on_raw[axis]);
            previous[axis].ambient_celsius = from_bits(c->previous[2 * axis]);
            previous[axis].switch_off_celsius = from_bits(c->previous[2 * axis + 1]);
        }
        uint16_t flags[GYRODRIFT_AXES];
        status = c->has_previous ? gyrodrift_power_on_after(&context, raw, previous, flags)
                                 : gyrodrift_power_on(&context, raw, flags);
        if ((status != GYRODRIFT_STATUS_OK) != c->power_on_fails) {
            printf("%s: power-on outcome differs (%d)\n", c->name, (int)status);
            return 1;
        }
    }
    size_t mismatches = 0;
    for (size_t i = 0; i < c->count; i++) {
        const uint32_t *in = &c->samples[7 * i];
        gyrodrift_sample sample = {.since_power_on_ms = in[0]};
        for (int axis = 0; axis < GYRODRIFT_AXES; axis++) {
            sample.rate_dps[axis] = from_bits(in[1 + axis]);
            sample.temperature_raw[axis] = from_bits(in[4 + axis]);
        }
        gyrodrift_output out;
        if (c->aux != NULL) {
            float aux[GYRODRIFT_AUX_INPUTS];
            for (int k = 0; k < GYRODRIFT_AUX_INPUTS; k++) {
                aux[k] = from_bits(c->aux[GYRODRIFT_AUX_INPUTS * i + k]);
            }
            status = gyrodrift_correct_with_aux(&context, &sample, aux, &out);
        } else {
            status = gyrodrift_correct(&context, &sample, &out);
        }
        if (status != GYRODRIFT_STATUS_OK) {
            printf("%s sample %u: gyrodrift_correct failed (%d)\n", c->name, (unsigned)i, (int)status);
            return mismatches + 1;
        }
        const uint32_t got[9] = {
            to_bits(out.corrected_dps[0]), to_bits(out.corrected_dps[1]), to_bits(out.corrected_dps[2]),
            to_bits(out.bias_dps[0]),      to_bits(out.bias_dps[1]),      to_bits(out.bias_dps[2]),
            out.flags[0],                  out.flags[1],                  out.flags[2],
        };
        for (int k = 0; k < 9; k++) {
            if (!same(c->expected[9 * i + k], got[k])) {
                mismatches++;
                printf("%s sample %u output %d: expected 0x%08lx, got 0x%08lx\n", c->name, (unsigned)i,
                       k, (unsigned long)c->expected[9 * i + k], (unsigned long)got[k]);
            }
        }
    }
    /* Before power-off: what the next activation reads. */
    if (c->has_previous && !c->power_on_fails) {
        if (gyrodrift_keep(&context, previous) != GYRODRIFT_STATUS_OK ||
            isnan(previous[0].switch_off_celsius)) {
            printf("%s: gyrodrift_keep recorded nothing\n", c->name);
            mismatches++;
        }
    }
    gyrodrift_power_off(&context);
    return mismatches;
}

int main(void) {
    initialise_monitor_handles();
    /* Misuse is an error code, not a crash. */
    static gyrodrift_context untouched;
    gyrodrift_output out;
    gyrodrift_sample sample = {0};
    if (gyrodrift_correct(&untouched, &sample, &out) != GYRODRIFT_STATUS_NOT_INITIALISED ||
        gyrodrift_init(NULL, NULL, 0) != GYRODRIFT_STATUS_NULL_POINTER) {
        printf("FAIL: misuse not reported\n");
        return 1;
    }
    size_t outputs = 0, mismatches = 0;
    for (size_t n = 0; n < vector_case_count; n++) {
        mismatches += run(&vector_cases[n]);
        outputs += 9 * vector_cases[n].count;
    }
    printf("context bytes: %u (sizeof gyrodrift_context)\n", (unsigned)sizeof context);
    printf("cases: %u (polynomial baselines left out: %u)\n", (unsigned)vector_case_count,
           (unsigned)vector_cases_skipped);
    printf("outputs compared: %u\n", (unsigned)outputs);
    printf("mismatches: %u\n", (unsigned)mismatches);
    if (mismatches != 0) {
        printf("FAIL: the C interface's outputs differ from the host's\n");
        return 1;
    }
    printf("PASS: C interface outputs on the Cortex-M4F are bit-identical to the host's\n");
    return 0;
}
