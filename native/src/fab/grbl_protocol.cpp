// GRBL's side of the conversation, free of any port: the lines a program may hold, the answers
// the controller sends, and what a program line says (its words, whether it only sets modes,
// whether GRBL answers it only once every queued move has run).
#include "grbl_protocol.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "wiresculpt/error.hpp"

namespace wiresculpt::fab {

void validate_program(const std::vector<std::string>& lines, const MachineProfile& profile) {
  const std::string allowed = std::string("GMFSPNT") + profile.axes.feed_axis + profile.axes.bend_axis +
                              (profile.axes.pin_axis ? std::string(1, profile.axes.pin_axis) : std::string());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const std::string who = "line " + std::to_string(i + 1);
    if (line.empty()) throw InputError(who + " is empty; remove blank lines (stream_lines() does)");
    if (line.size() > 79)
      throw InputError(who + " has " + std::to_string(line.size()) + " characters; GRBL accepts at most 79");
    for (char c : line) {
      const unsigned char u = static_cast<unsigned char>(c);
      if (u < 0x20 || u >= 0x7f) throw InputError(who + " contains a non-printable character");
      if (c == '!' || c == '~' || c == '?')
        throw InputError(who + " contains '" + std::string(1, c) + "', which GRBL executes as a realtime command");
      if (c == '(' || c == ';')
        throw InputError(who + " contains a comment; strip comments with stream_lines() before streaming");
    }
    if (line[0] == '$') continue;
    std::size_t k = 0;
    while (k < line.size()) {
      if (line[k] == ' ') { ++k; continue; }
      const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(line[k])));
      if (letter < 'A' || letter > 'Z' || allowed.find(letter) == std::string::npos)
        throw InputError(who + " ('" + line + "'): '" + std::string(1, line[k]) +
                         "' is not a G-code word this machine uses (allowed: " + allowed + ")");
      ++k;
      while (k < line.size() && line[k] == ' ') ++k;
      const std::size_t start = k;
      if (k < line.size() && (line[k] == '-' || line[k] == '+')) ++k;
      bool digits = false;
      while (k < line.size() && (std::isdigit(static_cast<unsigned char>(line[k])) || line[k] == '.')) {
        digits = digits || line[k] != '.';
        ++k;
      }
      if (!digits || k == start)
        throw InputError(who + " ('" + line + "'): the word '" + std::string(1, letter) + "' has no number");
    }
  }
}

namespace {

// The device's bytes as message text: "\r" dropped, any other byte outside printable ASCII
// (invalid UTF-8 included) shown as \xNN, so an answer always reaches the user as a string.
std::string printable(const std::string& raw) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (char c : raw) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u == '\r') continue;
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    }
  }
  return out;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

int code_after_colon(const std::string& s) {
  const std::size_t c = s.find(':');
  if (c == std::string::npos) return 0;
  try {
    return std::stoi(s.substr(c + 1));
  } catch (...) {
    return 0;
  }
}

std::string mm3(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return std::string(std::strcmp(buf, "-0.000") == 0 ? "0.000" : buf);
}

}  // namespace

GrblAnswer parse_answer(const std::string& raw) {
  GrblAnswer a;
  a.text = printable(raw);
  if (a.text == "ok") {
    a.kind = GrblAnswer::Kind::ok;
  } else if (starts_with(a.text, "error:")) {
    a.kind = GrblAnswer::Kind::error;
    a.code = code_after_colon(a.text);
  } else if (starts_with(a.text, "ALARM")) {
    a.kind = GrblAnswer::Kind::alarm;
    a.code = code_after_colon(a.text);
  } else if (starts_with(a.text, "Grbl ")) {
    a.kind = GrblAnswer::Kind::banner;
  }
  return a;
}

namespace detail {

// A line that only sets modes (units, distance mode, feed-rate mode, plane): G17-G19, G20/G21,
// G90/G91, G93/G94, nothing else but comments.
bool is_modal_setup(const std::string& line) {
  std::string code = line.substr(0, line.find(';'));
  for (std::size_t open; (open = code.find('(')) != std::string::npos;) {
    const std::size_t close = code.find(')', open);
    code.erase(open, close == std::string::npos ? std::string::npos : close - open + 1);
  }
  std::istringstream words(code);
  std::string word;
  int count = 0;
  while (words >> word) {
    for (char& c : word) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    static const char* const modal[] = {"G17", "G18", "G19", "G20", "G21", "G90", "G91", "G93", "G94"};
    if (std::find(std::begin(modal), std::end(modal), word) == std::end(modal)) return false;
    ++count;
  }
  return count > 0;
}

std::vector<Word> words_of(const std::string& line) {
  std::vector<Word> out;
  if (line.empty() || line[0] == '$') return out;
  std::string compact;
  for (char c : line)
    if (c != ' ' && c != '\t') compact += c;
  for (std::size_t k = 0; k < compact.size();) {
    const unsigned char c = static_cast<unsigned char>(compact[k]);
    if (!std::isalpha(c)) {
      ++k;
      continue;
    }
    std::size_t e = k + 1;
    std::string number;
    while (e < compact.size() && (std::isdigit(static_cast<unsigned char>(compact[e])) || compact[e] == '.' ||
                                  compact[e] == '-' || compact[e] == '+'))
      number += compact[e++];
    char* end = nullptr;
    const double v = number.empty() ? 0.0 : std::strtod(number.c_str(), &end);
    out.push_back({static_cast<char>(std::toupper(c)), std::isfinite(v) ? v : 0.0});
    k = e;
  }
  return out;
}

// A dwell (G4) or a program end (M2, M30): GRBL answers it only when every queued move has run,
// so its "ok" says that every line before it was executed, not only queued.
bool is_sync(const std::string& line) {
  for (const Word& w : words_of(line))
    if ((w.letter == 'G' && w.value == 4.0) || (w.letter == 'M' && (w.value == 2.0 || w.value == 30.0))) return true;
  return false;
}

bool is_dwell(const std::string& line) {
  for (const Word& w : words_of(line))
    if (w.letter == 'G' && w.value == 4.0) return true;
  return false;
}

// A line that moves nothing: done when its "ok" arrives with nothing queued before it.
bool is_motionless(const std::string& line) { return (!line.empty() && line[0] == '$') || is_modal_setup(line); }

// What lines a..b (0-based, inclusive) move: "feed 40.000 mm, bend 90.000 deg" (the bend as
// commanded, the first bend-axis G1 move; the head's return is not repeated, and the head's G0
// swing across the wire in a duck is the pin's move, not a bend).
std::string moves_of(const std::vector<std::string>& lines, const MachineProfile& profile, std::size_t a,
                     std::size_t b) {
  const AxisMapping& ax = profile.axes;
  const auto up = [](char c) { return static_cast<char>(std::toupper(static_cast<unsigned char>(c))); };
  double feed = 0.0, bend = 0.0;
  bool fed = false, bent = false, pin = false;
  for (std::size_t j = a; j <= b && j < lines.size(); ++j) {
    const std::vector<Word> words = words_of(lines[j]);
    const bool rapid = !words.empty() && words[0].letter == 'G' && words[0].value == 0.0;  // a duck's swing
    for (const Word& w : words) {
      if (w.letter == up(ax.feed_axis)) {
        feed += w.value;
        fed = true;
      } else if (w.letter == up(ax.bend_axis) && rapid) {
        pin = true;
      } else if (w.letter == up(ax.bend_axis) && !bent && w.value != 0.0) {
        bend = w.value;
        bent = true;
      } else if (ax.pin_axis != '\0' && w.letter == up(ax.pin_axis)) {
        pin = true;
      }
    }
  }
  std::string out;
  auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (fed) add("feed " + mm3(feed / ax.feed_units_per_mm) + " mm");
  if (pin) add("pin moved");
  if (bent) add("bend " + mm3(bend / ax.bend_units_per_deg * (profile.left_is_positive ? 1.0 : -1.0)) + " deg");
  return out.empty() ? "no feed or bend" : out;
}

}  // namespace detail

}  // namespace wiresculpt::fab
