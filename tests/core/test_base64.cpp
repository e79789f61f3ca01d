// Base64 against RFC 4648's test vectors (§10), and binary bytes that exercise every sextet.
#include <elastolearn/core/base64.hpp>

#include <gtest/gtest.h>

#include <vector>

namespace elastolearn {
namespace {

TEST(Base64, Rfc4648TestVectors) {
  EXPECT_EQ(base64_encode(std::string("")), "");
  EXPECT_EQ(base64_encode(std::string("f")), "Zg==");
  EXPECT_EQ(base64_encode(std::string("fo")), "Zm8=");
  EXPECT_EQ(base64_encode(std::string("foo")), "Zm9v");
  EXPECT_EQ(base64_encode(std::string("foob")), "Zm9vYg==");
  EXPECT_EQ(base64_encode(std::string("fooba")), "Zm9vYmE=");
  EXPECT_EQ(base64_encode(std::string("foobar")), "Zm9vYmFy");
}

TEST(Base64, HighBytesUseTheLastLettersOfTheAlphabet) {
  // 0xFB 0xFF 0xBF = 111110 111111 111110 111111: sextets 62, 63, 62, 63.
  const std::vector<std::byte> bytes
      = { std::byte { 0xFB }, std::byte { 0xFF }, std::byte { 0xBF } };
  EXPECT_EQ(base64_encode(bytes), "+/+/");
  const std::vector<std::byte> zeros(4, std::byte { 0 });
  EXPECT_EQ(base64_encode(zeros), "AAAAAA==");
}

} // namespace
} // namespace elastolearn
