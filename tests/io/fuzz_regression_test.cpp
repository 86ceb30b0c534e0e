// Replays every input that once crashed, leaked or tripped a sanitizer in a fuzz target
// (tests/fuzz/regressions/<target>/): each must now give a volume or mesh or one InputError.
// Under the asan preset this also re-checks them for memory errors. The specific findings get
// their exact messages below (docs/ROBUSTNESS.md lists them).
#include <filesystem>
#include <fstream>
#include <functional>
#include <gtest/gtest.h>
#include <string>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "cleave/io/json_fields.hpp"
#include "cleave/io/nifti_volume.hpp"
#include "cleave/io/nrrd_volume.hpp"
#include "io_fixtures.hpp"
#include "cleave/io/surface_mesh_file.hpp"

namespace cleave {
namespace {

const std::filesystem::path kRegressions = std::filesystem::path(CLEAVE_TEST_DATA_DIR) / "fuzz" / "regressions";

/// Runs `read` on every file of regressions/<target>/; returns how many there were.
template <typename Read>
int replay(const std::string& target, Read read) {
  int files = 0;
  const auto folder = kRegressions / target;
  if (!std::filesystem::is_directory(folder)) return 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    ++files;
    try {
      read(entry.path());
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << entry.path() << ": " << e.what();
    }
  }
  return files;
}

using test::input_error_of;

TEST(FuzzRegressions, EveryFormerCrashGivesAResultOrOneInputError) {
  int files = 0;
  files += replay("nrrd", [](const auto& p) { (void)read_nrrd_volume(p); });
  files += replay("nifti", [](const auto& p) { (void)read_nifti_volume(p); });
  for (const char* format : {"mesh_obj", "mesh_stl", "mesh_ply", "mesh_off"})
    files += replay(format, [](const auto& p) { (void)read_surface_mesh(p, 1.0); });
  EXPECT_GE(files, 2);
}

// fuzz_nifti: a NIfTI-2 header with dim[0] = 2^32 + 3 overflowed nifticlib's stack in
// nifti_image_read (it copies dim[1..dim[0]] into an array of 8).
TEST(FuzzRegressions, NiftiDimensionCountOutOfRange) {
  const auto file = kRegressions / "nifti" / "nifti2_dim0_overflow.nii";
  EXPECT_EQ(input_error_of([&] { (void)read_nifti_volume(file); }),
            file.string() + ": header dim[0] is 4294967299; expected 1 to 7 dimensions");
}

// fuzz_nifti (2 h campaign): a 348-byte NIfTI-1 header declaring 5.7 GB of samples made
// nifti_image_load allocate them all before finding the data missing.
TEST(FuzzRegressions, NiftiDeclaringMoreSamplesThanTheFileHoldsIsRefusedBeforeAllocating) {
  const auto file = kRegressions / "nifti" / "header_declares_5_7_GB.nii";
  const std::string error = input_error_of([&] { (void)read_nifti_volume(file); });
  EXPECT_EQ(error.rfind(file.string() + ": the image data is truncated or unreadable (expected ", 0), 0u) << error;
}

// fuzz_nifti (2 h campaign): a NIfTI-2 header stored byte-swapped (sizeof_hdr reads 540 only
// swapped) whose dim[0] reads 1 as stored and 2^56 swapped: cleave checked the stored value,
// nifticlib used the swapped one and overflowed its stack copying dim[1..dim[0]].
TEST(FuzzRegressions, ByteSwappedNifti2DimensionCountIsJudgedSwapped) {
  const auto file = kRegressions / "nifti" / "nifti2_swapped_dim0_overflow.nii";
  EXPECT_EQ(input_error_of([&] { (void)read_nifti_volume(file); }),
            file.string() + ": header dim[0] is 72057594037927936; expected 1 to 7 dimensions");
}

// fuzz_nrrd: bytes without the NRRD magic went to teem's other readers (plain text here), which
// leak on their error paths.
TEST(FuzzRegressions, NrrdWithoutMagicIsRefusedBeforeTeem) {
  const auto file = kRegressions / "nrrd" / "no_magic_teem_leak.nrrd";
  EXPECT_EQ(input_error_of([&] { (void)read_nrrd_volume(file); }),
            file.string() + ": not a NRRD file (expected the magic 'NRRD000' at the start)");
}

// fuzz_mesh_ply: an ASCII PLY whose first face line is garbage gave assimp a face with no
// corners, and its Triangulate step aborted the process.
TEST(FuzzRegressions, PlyFaceWithoutCornersIsRefusedBeforePostProcessing) {
  const auto file = kRegressions / "mesh_ply" / "ascii_face_without_corners.ply";
  // The ASCII walk before assimp now refuses its non-numeric list count; the check of imported
  // faces stays behind it as a second guard.
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }).rfind(file.string() + ": element 'face' 0 has a list of '", 0),
            0u);
}

// fuzz_mesh_ply (2 h campaign): after 73 min an ASan quarantine check failed inside assimp's PLY
// importer (heap corruption by the uninstrumented library, on one of the malformed ASCII bodies
// fed to it); this input was the last. The ASCII body is now walked before assimp: values must
// be numbers of their type, lines may not hold more values than their properties, face indices
// must name vertices of the file.
// PLY is now read by cleave's own parser (ply_mesh_file), which refuses this input's misspelt
// face list before reading the body.
TEST(FuzzRegressions, MalformedAsciiPlyBodiesNeverReachAssimp) {
  const auto file = kRegressions / "mesh_ply" / "ascii_body_garbage_heap_corruption.ply";
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
            file.string() + ": PLY element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
  test::TempFolder tmp;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const auto error_for = [&](const std::string& body) {
    test::write_bytes(tmp / "m.ply", header + body);
    return input_error_of([&] { (void)read_surface_mesh(tmp / "m.ply", 1.0); });
  };
  const std::string m = (tmp / "m.ply").string();
  EXPECT_EQ(error_for("0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n"), m + ": element 'vertex' 2 has the value 'zero'; expected a number");
  EXPECT_EQ(error_for("0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n"), m + ": element 'vertex' 2 has the value 'nan'; expected a number");
  EXPECT_EQ(error_for("0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n"), m + ": element 'face' 0 has the value '2.5'; expected a number");
  EXPECT_EQ(error_for("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), m + ": element 'face' 0 refers to vertex 3; the file has 3 vertices");
  EXPECT_EQ(error_for("0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), m + ": element 'face' 0 refers to vertex -1; the file has 3 vertices");
  // Well-formed: signs, exponents, blank lines and trailing blanks are fine.
  test::write_bytes(tmp / "ok.ply", header + "-0.5 +0 1e-3\n\n1.5E2 0 0  \n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_surface_mesh(tmp / "ok.ply", 1.0).triangles.size(), 1u);
}

// fuzz_mesh_ply (third leg, on the code with the ASCII body walk): the same heap corruption
// inside assimp after 15 min; the last input had no format line and element lines with trailing
// garbage ("element fac 0.0ace 13"), which the header check let through. Header lines are now
// exact: one format line before the elements, whole element counts, nothing after a line's fields.
TEST(FuzzRegressions, PlyHeaderLinesMustBeExact) {
  const auto file = kRegressions / "mesh_ply" / "header_garbage_heap_corruption.ply";
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
            file.string() + ": malformed PLY header line 'element fac 0.0ace 13'");
  test::TempFolder tmp;
  const auto error_for = [&](const std::string& header) {
    test::write_bytes(tmp / "h.ply", header + "end_header\n0 0 0\n");
    return input_error_of([&] { (void)read_surface_mesh(tmp / "h.ply", 1.0); });
  };
  const std::string h = (tmp / "h.ply").string();
  EXPECT_EQ(error_for("ply\nelement vertex 1\nproperty float x\n"),
            h + ": the PLY header has no format line; expected 'format ascii 1.0', 'format binary_little_endian 1.0' or "
                "'format binary_big_endian 1.0' before the elements");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
            h + ": malformed PLY header line 'format ascii 1.0'");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement vertex 1 2\nproperty float x\n"),
            h + ": malformed PLY header line 'element vertex 1 2'");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement vertex 1.5\nproperty float x\n"),
            h + ": malformed PLY header line 'element vertex 1.5'");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n"),
            h + ": malformed PLY header line 'property float'");
  EXPECT_EQ(error_for("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x y\n"),
            h + ": malformed PLY header line 'property float x y'");
}

// fuzz_mesh_ply: a binary PLY header without end_header made assimp read past its buffer.
TEST(FuzzRegressions, PlyWithoutEndHeaderIsRefusedBeforeAssimp) {
  const auto file = kRegressions / "mesh_ply" / "binary_without_end_header.ply";
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
            file.string() + ": not a PLY file (expected 'ply' first and an 'end_header' line)");
}

// fuzz_mesh_ply: two headers made assimp's PLY parser loop for more than 25 s: unknown lines
// ("propert", "y double motz") without a proper end, and "end_headerint" as the last line.
TEST(FuzzRegressions, PlyHeadersThatHungAssimpAreRefused) {
  for (const char* name : {"unknown_header_lines_hang.ply", "end_header_suffix_hang.ply"}) {
    const auto file = kRegressions / "mesh_ply" / name;
    EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
              file.string() + ": not a PLY file (expected 'ply' first and an 'end_header' line)");
  }
  const auto file = std::filesystem::temp_directory_path() / ("cleave_unknown_line_" + std::to_string(::getpid()) + ".ply");
  {
    std::ofstream out(file, std::ios::binary);
    out << "ply\nformat ascii 1.0\nelement vertex 1\npropert\xe3y float x\nend_header\n0\n";
  }
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
            file.string() + ": malformed PLY header line 'propert\xEF\xBF\xBDy float x'");
  std::filesystem::remove(file);
}

// fuzz_mesh_ply: a misspelt format ("binary_big_endia\xee") and an element name starting with
// digits made assimp allocate 64 GB; the format, its version and element names are checked first.
TEST(FuzzRegressions, PlyUnknownFormatIsRefusedBeforeAssimp) {
  const auto file = kRegressions / "mesh_ply" / "unknown_format_huge_allocation.ply";
  EXPECT_EQ(input_error_of([&] { (void)read_surface_mesh(file, 1.0); }),
            file.string() + ": malformed PLY header line 'format binary_big_endia\xEF\xBF\xBD 1.0'");
}

bool is_valid_utf8(const std::string& s) {
  try {
    (void)nlohmann::json(s).dump();
    return true;
  } catch (const nlohmann::json::exception&) {
    return false;
  }
}

// fuzz_studio_message: a message with invalid UTF-8 inside a string made nlohmann quote the raw
// bytes in its parse error; the studio put that text in its error reply, and dumping the reply
// threw (an exception out of the server's read handler ends the server).
TEST(FuzzRegressions, JsonErrorMessagesAreValidUtf8) {
  const std::string bad = "{\"cmd\": \"\xf9\xf9vtu\"}";
  const std::string message = input_error_of([&] { (void)parse_json_text(bad, "message"); });
  EXPECT_NE(message.find("invalid JSON at byte"), std::string::npos) << message;
  EXPECT_TRUE(is_valid_utf8(message)) << message;
  // A value quoted in an error is cut at 60 bytes without splitting a character.
  const std::string long_value(30, 'x');
  const std::string accented = long_value + "\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9";
  const std::string quoted = input_error_of([&] { json_error(JsonPath{"f", "/cmd"}, nlohmann::json(accented), "a name"); });
  EXPECT_TRUE(is_valid_utf8(quoted)) << quoted;
}

TEST(Utf8, SanitizedReplacesMalformedBytesAndKeepsValidText) {
  EXPECT_EQ(utf8_sanitized("abc"), "abc");
  EXPECT_EQ(utf8_sanitized("\xc3\xa9"), "\xc3\xa9");                       // e acute
  EXPECT_EQ(utf8_sanitized("a\xff" "b"), "a\xef\xbf\xbd" "b");             // stray byte
  EXPECT_EQ(utf8_sanitized("\xc0\xaf"), "\xef\xbf\xbd\xef\xbf\xbd");      // overlong '/'
  EXPECT_EQ(utf8_sanitized("\xed\xa0\x80"), "\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd");  // surrogate
  EXPECT_EQ(utf8_sanitized("\xe2\x82"), "\xef\xbf\xbd\xef\xbf\xbd");      // truncated euro sign
}

TEST(Utf8, PrefixNeverCutsACharacter) {
  EXPECT_EQ(utf8_prefix("abc", 10), "abc");
  EXPECT_EQ(utf8_prefix("ab\xc3\xa9", 3), "ab");
  EXPECT_EQ(utf8_prefix("ab\xc3\xa9", 4), "ab\xc3\xa9");
  EXPECT_EQ(utf8_prefix("\xe2\x82\xac\xe2\x82\xac", 5), "\xe2\x82\xac");
}

}  // namespace
}  // namespace cleave
