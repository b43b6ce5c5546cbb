// GRBL's protocol read without a port: the answer classifier, the program check and the G-code
// lexer the streamer's accounting rests on. Every expected value is worked out by hand from the
// line it is read from.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "fab/grbl_protocol.hpp"
#include "wiresculpt/error.hpp"
#include "wiresculpt/fab/serial.hpp"

using namespace wiresculpt;
using namespace wiresculpt::fab;
using namespace wiresculpt::fab::detail;

TEST_CASE("grbl protocol: a line's words are its letters in upper case and their numbers", "[fab][grbl]") {
  const std::vector<Word> w = words_of("g1 X40.5 y-90");
  REQUIRE(w.size() == 3);
  CHECK(w[0].letter == 'G');
  CHECK(w[0].value == 1.0);
  CHECK(w[1].letter == 'X');
  CHECK(w[1].value == 40.5);
  CHECK(w[2].letter == 'Y');
  CHECK(w[2].value == -90.0);
  SECTION("spaces between a letter and its number, and none between words") {
    const std::vector<Word> v = words_of("G1X10 Y 5");
    REQUIRE(v.size() == 3);
    CHECK(v[1].letter == 'X');
    CHECK(v[1].value == 10.0);
    CHECK(v[2].letter == 'Y');
    CHECK(v[2].value == 5.0);
  }
  SECTION("a letter without a number reads as 0; $ lines and empty lines have no words") {
    const std::vector<Word> v = words_of("M");
    REQUIRE(v.size() == 1);
    CHECK(v[0].value == 0.0);
    CHECK(words_of("$X").empty());
    CHECK(words_of("").empty());
  }
}

TEST_CASE("grbl protocol: mode lines, sync lines, dwells and motionless lines", "[fab][grbl]") {
  CHECK(is_modal_setup("G21 G90"));
  CHECK(is_modal_setup("g91"));
  CHECK(is_modal_setup("G17 (plane) G94 ; feed per minute"));
  CHECK_FALSE(is_modal_setup("G91 G1 X5"));
  CHECK_FALSE(is_modal_setup(""));
  CHECK_FALSE(is_modal_setup("(only a comment)"));

  CHECK(is_sync("G4 P0"));
  CHECK(is_sync("M2"));
  CHECK(is_sync("M30"));
  CHECK_FALSE(is_sync("G40"));  // G40 is not G4
  CHECK_FALSE(is_sync("M3 S100"));
  CHECK_FALSE(is_sync("G1 X4"));

  CHECK(is_dwell("G4 P0.5"));
  CHECK_FALSE(is_dwell("M2"));

  CHECK(is_motionless("$X"));
  CHECK(is_motionless("G21"));
  CHECK_FALSE(is_motionless("G1 X1"));
  CHECK_FALSE(is_motionless(""));
}

TEST_CASE("grbl protocol: the moves of a step are its feed, its pin and its first bend", "[fab][grbl]") {
  const std::vector<std::string> lines = {"G91", "G1 X25 F500", "G1 X15", "G1 Z5", "G1 Y90", "G1 Y-90", "G4 P0"};
  MachineProfile p;
  CHECK(moves_of(lines, p, 0, 6) == "feed 40.000 mm, pin moved, bend 90.000 deg");
  CHECK(moves_of(lines, p, 0, 0) == "no feed or bend");
  CHECK(moves_of(lines, p, 4, 100) == "bend 90.000 deg");  // past the end: up to the last line
  p.left_is_positive = false;
  p.axes.feed_units_per_mm = 2.0;
  p.axes.bend_units_per_deg = 0.5;
  CHECK(moves_of(lines, p, 1, 5) == "feed 20.000 mm, pin moved, bend -180.000 deg");
  p.axes.pin_axis = '\0';
  CHECK(moves_of(lines, p, 3, 3) == "no feed or bend");
  CHECK(moves_of({"G1 Y-0.0001"}, MachineProfile{}, 0, 0) == "bend 0.000 deg");  // never "-0.000"
}

TEST_CASE("grbl protocol: answers are classified by their exact form", "[fab][grbl]") {
  CHECK(parse_answer("ok").kind == GrblAnswer::Kind::ok);
  CHECK(parse_answer("ok\r").kind == GrblAnswer::Kind::ok);
  CHECK(parse_answer("okay").kind == GrblAnswer::Kind::info);
  const GrblAnswer e = parse_answer("error:22");
  CHECK(e.kind == GrblAnswer::Kind::error);
  CHECK(e.code == 22);
  const GrblAnswer a = parse_answer("ALARM:3");
  CHECK(a.kind == GrblAnswer::Kind::alarm);
  CHECK(a.code == 3);
  CHECK(parse_answer("Grbl 1.1h ['$' for help]").kind == GrblAnswer::Kind::banner);
  CHECK(parse_answer("error:x").code == 0);
  CHECK(parse_answer(std::string("ok\x01", 3)).text == "ok\\x01");
}

TEST_CASE("grbl protocol: a program line holds only the machine's words", "[fab][grbl]") {
  const MachineProfile p;  // axes X (feed), Y (bend), Z (pin)
  CHECK_NOTHROW(validate_program({"G21 G91", "G1 X10 F500", "$X", "G4 P0"}, p));
  CHECK_THROWS_AS(validate_program({"G1 A10"}, p), InputError);   // A is no axis of this machine
  CHECK_THROWS_AS(validate_program({"G1 X"}, p), InputError);     // a word without a number
  CHECK_THROWS_AS(validate_program({"G1 X1", ""}, p), InputError);
  CHECK_THROWS_AS(validate_program({"G1 X1 ; feed"}, p), InputError);
  CHECK_THROWS_AS(validate_program({"G1 X1!"}, p), InputError);
  CHECK_THROWS_AS(validate_program({std::string(80, 'G')}, p), InputError);
}
