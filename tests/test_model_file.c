/* The model file loader's own pieces: SHA-256 against the FIPS 180-4 /
 * NIST test vectors, the API contract (nothing filled on failure, messages
 * truncated to msglen), and the load time of models/4prru.json. The
 * rules themselves are checked against the generator by
 * tests/model_conformance.py. */
#include <stdio.h>
#include <string.h>

#include "../runtime/src/sha256.h"
#include "prru_model_file.h"

static int fails;

static void check(int ok, const char *what)
{
  if (!ok) {
    printf("FAIL %s\n", what);
    fails++;
  }
}

static void vectors(void)
{
  static const char *const in[] = {
    "", "abc", "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",
    "abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnop"
    "jklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu"};
  static const char *const out[] = {
    "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855",
    "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad",
    "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1",
    "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1"};
  static char million[1000000];
  char hex[65];
  prru_sha256_ctx c;
  unsigned char d[32];
  int i;
  for (i = 0; i < 4; i++) {
    prru_sha256_hex(in[i], strlen(in[i]), hex);
    check(strcmp(hex, out[i]) == 0, in[i]);
  }
  memset(million, 'a', sizeof million);
  prru_sha256_hex(million, sizeof million, hex);
  check(strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0") == 0,
        "one million a");
  /* the same bytes fed in uneven pieces across block boundaries */
  prru_sha256_init(&c);
  for (i = 0; i < 1000000; i += 997)
    prru_sha256_update(&c, million + i, i + 997 <= 1000000 ? 997 : 1000000 - i);
  prru_sha256_final(&c, d);
  prru_sha256_to_hex(d, hex);
  check(strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0") == 0,
        "one million a in pieces");
}

static void contract(void)
{
  prru_model_spec m, before;
  char msg[24];
  const char bad[] = "{\"name\": \"x\"}";
  memset(&m, 0x5a, sizeof m);
  before = m;
  check(prru_model_file_parse(bad, strlen(bad), "f.json", &m, msg, sizeof msg)
        == PRRU_EPARSE, "a refused file is PRRU_EPARSE");
  check(memcmp(&m, &before, sizeof m) == 0, "nothing filled on failure");
  check(strcmp(msg, "f.json: description: mi") == 0, "message cut to msglen");
  check(prru_model_file_read("/nonexistent/m.json", &m, NULL, 0) == PRRU_EIO,
        "an unreadable file is PRRU_EIO");
  check(memcmp(&m, &before, sizeof m) == 0, "nothing filled on failure");
}

int main(void)
{
  vectors();
  contract();
  if (!fails)
    printf("sha256 vectors and the loader's contract: ok\n");
  return fails != 0;
}
