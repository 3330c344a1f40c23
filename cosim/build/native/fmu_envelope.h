/*
 * fmu_envelope.h: the envelope every arcosim FMU puts around a serialized FMU state,
 * and its check. ISO C99, header only (static functions): the plant FMU ships it in
 * its sources/, the Python FMUs' trampoline is compiled with it.
 *
 * Layout, little-endian:
 *   0  magic "ARCOSIMS"              8 bytes
 *   8  format version                4
 *  12  flags (the FMU's own)         4
 *  16  time (IEEE double)            8
 *  24  n, the number of load masses  4
 *  28  identity length L             4
 *  32  identity "<model identifier> <GUID> <build>"   L
 *  32+L payload length P             8
 *  40+L payload                      P
 *  40+L+P CRC-32 of everything before it               4
 * A state is taken only if every field agrees with this FMU: another FMU's, another
 * build's, another n's, a truncated, padded or altered state is refused with the
 * reason, before a byte of it reaches the FMU.
 */
#ifndef ARCOSIM_FMU_ENVELOPE_H
#define ARCOSIM_FMU_ENVELOPE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define ENVELOPE_VERSION 1u
/* Bytes around a payload, for an identity of L bytes. */
#define ENVELOPE_OVERHEAD(L) (40 + (L) + 4)

static const char ENVELOPE_MAGIC[8] = {'A', 'R', 'C', 'O', 'S', 'I', 'M', 'S'};

static uint32_t envelope_crc32(const unsigned char *p, size_t n) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

static void envelope_put(unsigned char *p, uint64_t v, int bytes) {
    for (int i = 0; i < bytes; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t envelope_get(const unsigned char *p, int bytes) {
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++) v |= (uint64_t)p[i] << (8 * i);
    return v;
}

/* Where the payload goes in an envelope for an identity of L bytes. */
static unsigned char *envelope_payload(unsigned char *out, size_t identity_length) {
    return out + 40 + identity_length;
}

/* Write the envelope's head around a payload of ``payload`` bytes (written at
 * envelope_payload() by the caller, before envelope_seal). */
static void envelope_open(unsigned char *out, uint32_t flags, double time, uint32_t n,
                          const char *identity, size_t identity_length, uint64_t payload) {
    uint64_t time_bits;
    memcpy(&time_bits, &time, sizeof time_bits);
    memcpy(out, ENVELOPE_MAGIC, 8);
    envelope_put(out + 8, ENVELOPE_VERSION, 4);
    envelope_put(out + 12, flags, 4);
    envelope_put(out + 16, time_bits, 8);
    envelope_put(out + 24, n, 4);
    envelope_put(out + 28, identity_length, 4);
    memcpy(out + 32, identity, identity_length);
    envelope_put(out + 32 + identity_length, payload, 8);
}

/* Write the checksum of an envelope of ``total`` bytes (payload written). */
static void envelope_seal(unsigned char *out, size_t total) {
    envelope_put(out + total - 4, envelope_crc32(out, total - 4), 4);
}

/* Check ``size`` bytes against this FMU's identity and n. Returns NULL and sets the
 * payload's place and length, the flags and the time if the state is this FMU's;
 * else the reason, written into ``why``. */
static const char *envelope_check(const unsigned char *p, size_t size, const char *identity,
                                  size_t identity_length, uint32_t n, char *why,
                                  size_t why_size, const unsigned char **payload,
                                  uint64_t *payload_length, uint32_t *flags, double *time) {
    if (!p || size < 32) {
        snprintf(why, why_size, "%zu bytes are too few to be a serialized state of this FMU",
                 size);
        return why;
    }
    if (memcmp(p, ENVELOPE_MAGIC, 8) != 0) {
        snprintf(why, why_size, "the bytes are not an FMU state serialized by an arcosim FMU");
        return why;
    }
    uint32_t version = (uint32_t)envelope_get(p + 8, 4);
    if (version != ENVELOPE_VERSION) {
        snprintf(why, why_size, "state format version %u; this FMU reads version %u", version,
                 ENVELOPE_VERSION);
        return why;
    }
    uint64_t length = envelope_get(p + 28, 4);
    uint32_t theirs_n = (uint32_t)envelope_get(p + 24, 4);
    if (length > size - 32 || size - 32 - length < 12) {
        snprintf(why, why_size, "the identity field runs past the %zu bytes given (truncated?)",
                 size);
        return why;
    }
    if (length != identity_length || memcmp(p + 32, identity, identity_length) != 0 ||
        theirs_n != n) {
        char theirs[512];
        size_t shown = length < sizeof theirs - 1 ? (size_t)length : sizeof theirs - 1;
        memcpy(theirs, p + 32, shown);
        theirs[shown] = '\0';
        snprintf(why, why_size, "it is a state of '%s' with n = %u, not of this FMU '%s' with "
                 "n = %u", theirs, theirs_n, identity, n);
        return why;
    }
    uint64_t declared = envelope_get(p + 32 + identity_length, 8);
    if (declared != size - ENVELOPE_OVERHEAD(identity_length)) {
        snprintf(why, why_size, "its length field says %llu payload bytes, %zu arrived "
                 "(truncated or padded)", (unsigned long long)declared,
                 size >= ENVELOPE_OVERHEAD(identity_length)
                     ? size - ENVELOPE_OVERHEAD(identity_length)
                     : 0);
        return why;
    }
    if (envelope_crc32(p, size - 4) != (uint32_t)envelope_get(p + size - 4, 4)) {
        snprintf(why, why_size, "checksum mismatch: the bytes were altered after serialization");
        return why;
    }
    uint64_t time_bits = envelope_get(p + 16, 8);
    *payload = p + 40 + identity_length;
    *payload_length = declared;
    *flags = (uint32_t)envelope_get(p + 12, 4);
    memcpy(time, &time_bits, sizeof *time);
    return NULL;
}

#endif
