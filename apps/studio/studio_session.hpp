#pragma once
// A studio session: one model, the design edited on it (with undo / redo) and the journal that
// makes every acknowledged edit durable. It lives in a session folder:
//   session.json    {"cleave_session":1, "case":{...}}  the case the session started from
//   journal.jsonl   one line per acknowledged edit (session_journal.hpp)
//   *.json, *.vtu, *.ply, *.gltf                         saved cases and exports
// Opening a folder that holds a session replays its journal: the state is the last
// acknowledged one. Not thread safe: the server calls it from one thread.
//
//   StudioSession s(folder, case_document);     // or std::nullopt to reopen / use the default
//   std::uint64_t seq = s.apply_edit({{"cmd","add_stroke"},{"points_mm",...}});   // durable now
//   s.design();  s.seq();
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "cleave/io/case_file.hpp"
#include "cleave/model/tissue_model.hpp"
#include "studio/edit_history.hpp"
#include "studio/session_journal.hpp"

namespace cleave::studio {

/// The case a new session starts from on a bare model (a model name or file, no case file):
/// `model` is the case's "model" section. On the built-in abdomen the case also holds the demo's
/// design settings and supports (pipeline/demo_case.hpp, abdomen_demo_settings: no equilibrium
/// term, exact equilibration, the wall's rim and inner surface held), so the studio's preview
/// opens as `cleave demo` does; it builds the model to place the rim. Other models: the model only
/// (the library's defaults). InputError for a model that cannot be loaded.
nlohmann::json bare_model_case(const nlohmann::json& model);

/// The case a session starts from when neither the folder nor the command line names one: the
/// built-in abdomen at half the paper's resolution (63 x 21 x 42 cells, paper table 1), with the
/// demo's settings (bare_model_case).
nlohmann::json default_session_case();

class StudioSession {
 public:
  /// Opens or creates the session in `folder`. `case_document` (a validated case, model paths
  /// absolute) starts a new session; it must match the folder's session if the folder already
  /// has edits (InputError otherwise). std::nullopt reopens the folder's session or starts the
  /// default one. Loads the model and replays the journal.
  StudioSession(std::filesystem::path folder, std::optional<nlohmann::json> case_document);

  const std::filesystem::path& folder() const { return folder_; }
  const TissueModel& model() const { return *model_; }
  const nlohmann::json& case_document() const { return case_; }
  /// The same parsed (model source resolved against the session folder).
  const CaseFile& case_file() const { return *case_file_; }
  const DesignState& design() const { return history_.current(); }
  const EditHistory& history() const { return history_; }
  /// Number of acknowledged edits in this session (the journal's last seq).
  std::uint64_t seq() const { return journal_->last_seq(); }
  /// Bytes of a torn journal tail dropped when the session was opened.
  std::size_t torn_bytes_dropped() const { return journal_->torn_bytes_dropped(); }

  /// Validates and applies a design edit (design_edit.hpp) or {"cmd":"undo"} / {"cmd":"redo"},
  /// appends it to the journal (on disk when this returns) and returns its seq. On InputError
  /// nothing changes.
  std::uint64_t apply_edit(const nlohmann::json& edit);

  /// Writes the session's case with the current design to `file_name` inside the folder.
  std::filesystem::path save_case(const std::string& file_name) const;
  /// Reads a case from `file_name` inside the folder and returns the replace_design edit that
  /// loads its design (apply it with apply_edit). InputError for a bad case or another model.
  nlohmann::json load_case_edit(const std::string& file_name) const;

  /// {"type":"state","seq":N,"design":{...},"can_undo":b,"can_redo":b,"model":{...}}
  nlohmann::json state_message() const;

 private:
  void apply_in_memory(const nlohmann::json& edit, const std::string& where);

  std::filesystem::path folder_;
  nlohmann::json case_;
  std::unique_ptr<CaseFile> case_file_;
  std::unique_ptr<TissueModel> model_;
  EditHistory history_;
  std::unique_ptr<SessionJournal> journal_;
};

}  // namespace cleave::studio
