/// app/cutter_note.h: an APT file's CUTTER against the scene's tool.
#include <gtest/gtest.h>

#include "cutter_note.h"

namespace fieldpath::app::test {
namespace {

geometry::PathFile withCutters(std::vector<geometry::PathFile::Cutter> cutters) {
  geometry::PathFile path;
  path.file = "job.apt";
  path.cutters = std::move(cutters);
  return path;
}

TEST(CutterNotes, SaidWhenTheFileWasWrittenForAnotherTool) {
  geometry::ToolSpec ball;  // ball, R 3
  ball.radius_mm = 3.0;
  EXPECT_TRUE(cutterNotes(ball, withCutters({})).empty());
  // the same tool: diameter 6, corner 3, within 1 um (inches converted)
  EXPECT_TRUE(cutterNotes(ball, withCutters({{6.0, 3.0, 4}, {0.23622 * 25.4, 3.0, 12}})).empty());
  // CUTTER/6 alone is, in APT, a flat end mill: said against a ball, not against a flat one
  const auto bare = cutterNotes(ball, withCutters({{6.0, -1.0, 9}}));
  ASSERT_EQ(bare.size(), 1u);
  EXPECT_EQ(bare[0],
            "job.apt:9: CUTTER says the path was written for a 6 mm cutter with no corner radius "
            "given (in APT, a flat end mill); the scene's tool is a ball of radius 3 mm (6 mm): "
            "what follows is for the scene's tool, not the file's");
  geometry::ToolSpec flat;
  flat.shape = geometry::ToolShape::Flat;
  flat.radius_mm = 3.0;
  EXPECT_TRUE(cutterNotes(flat, withCutters({{6.0, -1.0, 9}, {6.0, 0.0, 10}})).empty());
  const auto other = cutterNotes(ball, withCutters({{10.0, 5.0, 4}}));
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0],
            "job.apt:4: CUTTER says the path was written for a 10 mm cutter with a 5 mm corner; "
            "the scene's tool is a ball of radius 3 mm (6 mm): what follows is for the scene's "
            "tool, not the file's");
  // a diameter not > 0 (`CUTTER/-6`, a typo or a placeholder) gives no tool: said so
  const auto none = cutterNotes(ball, withCutters({{-6.0, 3.0, 5}}));
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0],
            "job.apt:5: CUTTER gives a diameter of -6 mm, no tool: the file does not say which "
            "cutter it was written for; what follows is for the scene's tool, a ball of radius "
            "3 mm (6 mm)");
  // a flat end mill of the same diameter differs by its corner
  EXPECT_EQ(cutterNotes(ball, withCutters({{6.0, 0.0, 7}})).size(), 1u);
  geometry::ToolSpec torus;
  torus.shape = geometry::ToolShape::Torus;
  torus.radius_mm = 5.0;
  torus.corner_radius_mm = 1.0;
  EXPECT_TRUE(cutterNotes(torus, withCutters({{10.0, 1.0, 2}})).empty());
  // many: two lines and a count
  const auto many =
      cutterNotes(ball, withCutters({{8, -1, 1}, {8, -1, 2}, {8, -1, 3}, {8, -1, 4}, {8, -1, 5}}));
  ASSERT_EQ(many.size(), 3u);
  EXPECT_EQ(many[2], "job.apt: 3 more CUTTER / TLDATA records differ from the scene's tool");
}

TEST(CutterNotes, SaidWhenTheFilesToolIsAnotherLength) {
  // CUTTER's h and TLDATA's l are the tool's length: the holder sits there (a blisk helper's file
  // said 40 mm against the scene's 60 and went unsaid).
  geometry::ToolSpec ball;
  ball.radius_mm = 3.0;
  ball.length_mm = 60.0;
  // The one note for a record of diameter d, corner r and length at `line` ("" where none).
  const auto noteFor = [&](double d, double r, double length_mm, std::size_t line,
                           const char* record = "CUTTER") {
    geometry::PathFile::Cutter cutter{d, r, line, record};
    cutter.length_mm = length_mm;
    const std::vector<std::string> notes = cutterNotes(ball, withCutters({cutter}));
    EXPECT_LE(notes.size(), 1u);
    return notes.empty() ? std::string() : notes[0];
  };
  EXPECT_EQ(noteFor(6.0, 3.0, 60.0 + 5e-4, 4), "");  // within 1 um
  EXPECT_EQ(noteFor(6.0, 3.0, 40.0, 5),
            "job.apt:5: CUTTER says the tool is 40 mm long (tip to holder); the scene's "
            "tool.length_mm is 60: with the file's tool the holder sits 20 mm lower, nearer the "
            "part, than the scene proves it; give tool.length_mm the length the machine runs");
  const std::string high = noteFor(6.0, 3.0, 75.0, 6, "TLDATA");
  EXPECT_NE(high.find("job.apt:6: TLDATA says the tool is 75 mm long"), std::string::npos);
  EXPECT_NE(high.find("sits 15 mm higher"), std::string::npos);
  // with another diameter too: one line naming both tools' lengths
  EXPECT_EQ(noteFor(10.0, 5.0, 40.0, 7),
            "job.apt:7: CUTTER says the path was written for a 10 mm cutter with a 5 mm corner, "
            "40 mm long; the scene's tool is a ball of radius 3 mm (6 mm), 60 mm long: what "
            "follows is for the scene's tool, not the file's");
}

}  // namespace
}  // namespace fieldpath::app::test
