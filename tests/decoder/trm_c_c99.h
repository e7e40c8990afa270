/* The C side of the C API tests (trm_c_c99.c, compiled as C99). */
#ifndef TRM_TESTS_TRM_C_C99_H
#define TRM_TESTS_TRM_C_C99_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Decodes `views` views of one full size through one handle (json NULL: trm_config_defaults), pushing line by line
 * (codes[v]: the view's input lines back to back; intact NULL, or intact[v] NULL: every line intact) and popping
 * every ready row after each push into drive (views x full_height rows of 3 x full_width samples). Returns 0, a
 * trm_status, or 100+ for a broken API promise (rows out of order, rows missing, no report); message gets the error. */
int c99_decode_views(const char* json, int32_t full_width, int32_t full_height, int32_t views,
                     const int32_t* kinds, const int32_t* eyes, const int64_t* indices, const uint16_t* const* codes,
                     const uint8_t* const* intact, uint16_t* drive, char* message, size_t message_capacity);

#ifdef __cplusplus
}
#endif

#endif
