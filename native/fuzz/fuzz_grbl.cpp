// libFuzzer target: the GRBL response parser (parse_answer), on arbitrary device bytes split into
// lines. Every line must be classified without throwing, its text printable ASCII (a message can
// quote it; invalid UTF-8 once raised UnicodeDecodeError in Python), and only an exact "ok"
// (after dropping "\r") may count as an acknowledgement.
#include <fuzzer/FuzzedDataProvider.h>

#include <string>

#include "wiresculpt/fab/serial.hpp"

using namespace wiresculpt::fab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::size_t start = 0;
  while (start <= bytes.size()) {
    std::size_t nl = bytes.find('\n', start);
    if (nl == std::string::npos) nl = bytes.size();
    const std::string raw = bytes.substr(start, nl - start);
    const GrblAnswer a = parse_answer(raw);
    for (char c : a.text)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) __builtin_trap();
    std::string stripped;
    for (char c : raw)
      if (c != '\r') stripped += c;
    if ((a.kind == GrblAnswer::Kind::ok) != (stripped == "ok")) __builtin_trap();
    start = nl + 1;
  }
  return 0;
}
