/* SHA-256 as specified by FIPS 180-4, section 6.2. */
#include "sha256.h"

#include <string.h>

static const uint32_t K[64] = {
  0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1,
  0x923f82a4, 0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3,
  0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
  0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
  0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147,
  0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
  0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
  0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
  0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
  0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208,
  0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

static uint32_t rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

static void compress(uint32_t h[8], const unsigned char *p)
{
  uint32_t w[64], s[8];
  int t;
  for (t = 0; t < 16; t++)
    w[t] = (uint32_t)p[4 * t] << 24 | (uint32_t)p[4 * t + 1] << 16
           | (uint32_t)p[4 * t + 2] << 8 | (uint32_t)p[4 * t + 3];
  for (t = 16; t < 64; t++) {
    uint32_t s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
    uint32_t s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
    w[t] = w[t - 16] + s0 + w[t - 7] + s1;
  }
  memcpy(s, h, sizeof s);
  for (t = 0; t < 64; t++) {
    uint32_t e = s[4], a = s[0];
    uint32_t t1 = s[7] + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25))
                  + ((e & s[5]) ^ (~e & s[6])) + K[t] + w[t];
    uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22))
                  + ((a & s[1]) ^ (a & s[2]) ^ (s[1] & s[2]));
    memmove(s + 1, s, 7 * sizeof *s);
    s[4] += t1;
    s[0] = t1 + t2;
  }
  for (t = 0; t < 8; t++)
    h[t] += s[t];
}

void prru_sha256_init(prru_sha256_ctx *c)
{
  static const uint32_t h0[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372,
                                 0xa54ff53a, 0x510e527f, 0x9b05688c,
                                 0x1f83d9ab, 0x5be0cd19};
  memcpy(c->h, h0, sizeof h0);
  c->nbytes = 0;
  c->fill = 0;
}

void prru_sha256_update(prru_sha256_ctx *c, const void *data, size_t len)
{
  const unsigned char *p = data;
  c->nbytes += len;
  while (len > 0) {
    size_t n = 64 - c->fill < len ? 64 - c->fill : len;
    if (c->fill == 0 && len >= 64) {
      compress(c->h, p);
      n = 64;
    } else {
      memcpy(c->block + c->fill, p, n);
      c->fill += n;
      if (c->fill == 64) {
        compress(c->h, c->block);
        c->fill = 0;
      }
    }
    p += n;
    len -= n;
  }
}

void prru_sha256_final(prru_sha256_ctx *c, unsigned char digest[32])
{
  uint64_t bits = c->nbytes * 8;
  unsigned char pad[72] = {0x80};
  size_t padlen = (c->fill < 56 ? 56 : 120) - c->fill;
  int i;
  for (i = 0; i < 8; i++)
    pad[padlen + i] = (unsigned char)(bits >> (56 - 8 * i));
  prru_sha256_update(c, pad, padlen + 8);
  for (i = 0; i < 32; i++)
    digest[i] = (unsigned char)(c->h[i / 4] >> (24 - 8 * (i % 4)));
}

void prru_sha256_to_hex(const unsigned char digest[32], char hex[65])
{
  static const char digits[] = "0123456789abcdef";
  int i;
  for (i = 0; i < 32; i++) {
    hex[2 * i] = digits[digest[i] >> 4];
    hex[2 * i + 1] = digits[digest[i] & 15];
  }
  hex[64] = '\0';
}

void prru_sha256_hex(const void *data, size_t len, char hex[65])
{
  prru_sha256_ctx c;
  unsigned char d[32];
  prru_sha256_init(&c);
  prru_sha256_update(&c, data, len);
  prru_sha256_final(&c, d);
  prru_sha256_to_hex(d, hex);
}
