/* SHA-256 (FIPS 180-4), for the model file's hashes: small enough to keep
 * the library free of a crypto dependency. Internal to the runtime. */
#ifndef PRRU_SHA256_H
#define PRRU_SHA256_H
#include <stddef.h>
#include <stdint.h>

typedef struct {
  uint32_t h[8];
  uint64_t nbytes;
  unsigned char block[64];
  size_t fill;
} prru_sha256_ctx;

void prru_sha256_init(prru_sha256_ctx *c);
void prru_sha256_update(prru_sha256_ctx *c, const void *data, size_t len);
void prru_sha256_final(prru_sha256_ctx *c, unsigned char digest[32]);
/* The digest of data as 64 lower-case hex digits and a NUL. */
void prru_sha256_hex(const void *data, size_t len, char hex[65]);
void prru_sha256_to_hex(const unsigned char digest[32], char hex[65]);

#endif
