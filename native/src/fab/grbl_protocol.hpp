#pragma once
// What a (validated) program line says to GRBL, read without a port: the streamer's accounting
// of which lines are done rests on these. Public entry points of the protocol (parse_answer,
// validate_program) are in wiresculpt/fab/serial.hpp.
#include <cstddef>
#include <string>
#include <vector>

#include "wiresculpt/fab/serial.hpp"

namespace wiresculpt::fab::detail {

/// One word of a program line: its letter (upper case) and its number (0 when absent or not
/// finite).
struct Word {
  char letter;
  double value;
};

/// The words of a line in order; spaces and tabs are ignored, "$" lines have none.
std::vector<Word> words_of(const std::string& line);

/// A line that only sets modes (units, distance mode, feed-rate mode, plane): G17-G19,
/// G20/G21, G90/G91, G93/G94 and nothing else but comments.
bool is_modal_setup(const std::string& line);

/// A dwell (G4) or a program end (M2, M30): GRBL answers it only when every queued move has
/// run, so its "ok" says that every line before it was executed, not only queued.
bool is_sync(const std::string& line);

/// A dwell (G4): the end of each bend step in a bend program.
bool is_dwell(const std::string& line);

/// A line that moves nothing ("$" settings, mode lines): done when its "ok" arrives with nothing
/// queued before it.
bool is_motionless(const std::string& line);

/// What lines a..b (0-based, inclusive) move, e.g. "feed 40.000 mm, bend 90.000 deg": the feed
/// summed, the first non-zero bend-axis move as commanded (left positive), "pin moved" when the
/// pin axis moves; "no feed or bend" when none does.
std::string moves_of(const std::vector<std::string>& lines, const MachineProfile& profile, std::size_t a,
                     std::size_t b);

}  // namespace wiresculpt::fab::detail
