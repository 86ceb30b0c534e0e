// The volume and mesh entries of the bad-input catalogue (tests/bad_inputs/EXPECTED.tsv), loaded
// through the library: each gives one InputError line that starts with the file's path and
// contains the expected text (the CLI catalogue run checks the same files end to end).
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>

#include "cleave/core/error.hpp"
#include "cleave/io/model_source.hpp"

namespace cleave {
namespace {

struct CatalogueEntry {
  std::string file;
  std::string expected;
};

std::vector<CatalogueEntry> model_file_entries() {
  std::vector<CatalogueEntry> entries;
  std::ifstream in(std::string(CLEAVE_TEST_DATA_DIR) + "/bad_inputs/EXPECTED.tsv");
  for (std::string line; std::getline(in, line);) {
    std::istringstream columns(line);
    std::string file, command, expected;
    if (!std::getline(columns, file, '\t') || !std::getline(columns, command, '\t') || !std::getline(columns, expected))
      continue;
    if (file.rfind("volume_", 0) == 0 || file.rfind("mesh_", 0) == 0) entries.push_back({file, expected});
  }
  return entries;
}

TEST(BadModelFiles, EveryCatalogueVolumeAndMeshGivesItsNamedError) {
  const auto entries = model_file_entries();
  EXPECT_GE(entries.size(), 14u);
  for (const auto& [file, expected] : entries) {
    const std::string path = std::string(CLEAVE_TEST_DATA_DIR) + "/bad_inputs/" + file;
    std::string message = "no InputError";
    try {
      load_model_source(path, {});
    } catch (const InputError& e) {
      message = e.what();
    }
    EXPECT_EQ(message.rfind(std::string(CLEAVE_TEST_DATA_DIR) + "/bad_inputs/", 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << file << ": got '" << message << "'";
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

TEST(BadModelFiles, MissingVolumeAndMesh) {
  for (const std::string name : {"/nonexistent/scan.nii.gz", "/nonexistent/seg.nrrd", "/nonexistent/body.off"}) {
    try {
      load_model_source(name, {});
      ADD_FAILURE() << name;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), name + ": no such file");
    }
  }
}

}  // namespace
}  // namespace cleave
