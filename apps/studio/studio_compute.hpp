#pragma once
// The studio's computation side: after every edit it recomputes, in the field worker, what the
// page shows (the surface, the design fields and the incision preview), and it answers the
// requests that need the model (exports). It only calls the cleave library; the physics lives
// there. Results are JSON messages for the page (docs/studio.md), every number finite.
#include <future>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cleave/core/recent_results.hpp"
#include "cleave/cut/body_surface.hpp"
#include "cleave/cut/cut_plan.hpp"
#include "cleave/fem/static_solver.hpp"
#include "cleave/io/case_mechanics.hpp"
#include "cleave/solve/linear_solver.hpp"
#include "cleave/stress/line_field_interpolation.hpp"
#include "cleave/stress/stress_designer.hpp"
#include "cleave/surface/render_surface.hpp"
#include "cleave/surface/surface_mesh.hpp"
#include "cleave/viz/incision_ellipses.hpp"
#include "studio/cut_face_values.hpp"
#include "studio/broadcast_kind.hpp"
#include "studio/field_worker.hpp"
#include "studio/message_handler.hpp"
#include "studio/studio_session.hpp"

namespace cleave::studio {

class StudioCompute {
 public:
  /// `send` delivers a message to every client (thread safe; called from the worker thread):
  /// JSON text, or the binary form of wire_message.hpp for results and frames; its kind says
  /// which unsent message it may replace (broadcast_kind.hpp).
  /// `jobs`: where the computations run (FieldWorker::JobThread; `cleave studio`: its main
  /// thread, through run_jobs()).
  using Send = std::function<void(std::string, BroadcastKind)>;
  StudioCompute(const StudioSession& session, Send send,
                FieldWorker::JobThread jobs = FieldWorker::JobThread::own);
  ~StudioCompute();

  /// Starts recomputing for `design` (seq = the session's seq); a newer call supersedes it.
  void design_changed(const DesignState& design, std::uint64_t seq);
  /// The latest result message (the mesh and fields) for a newly connected client, with its
  /// triangles (a result sent to connected clients leaves them out when its surface is the one
  /// they already hold: docs/studio.md).
  std::vector<std::string> welcome_messages() const;
  /// Writes the latest result in `format` to `file`.
  void export_result(ExportFormat format, const std::filesystem::path& file) const;
  /// Blocks until the worker is idle (tests).
  void wait_idle() { worker_->wait_idle(); }
  /// FieldWorker::JobThread::caller: computes on this thread until stop_jobs() (FieldWorker::run_jobs).
  void run_jobs() { worker_->run_jobs(); }
  void stop_jobs() { worker_->stop(); }

 private:
  nlohmann::json compute(const DesignState& design, std::uint64_t seq, const FieldWorker::Context& ctx);
  /// Sends a "result" to every client and keeps it for those that connect later (worker thread).
  void publish_result(nlohmann::json message);
  /// After a picture drawn from a provisional stress: the equilibration's remaining steps, as a
  /// "design_final" message (the stress's residual display and cut-face tractions, the final
  /// residual); null when superseded (the next edit drops the provisional stress).
  nlohmann::json complete_design(std::uint64_t seq, const FieldWorker::Context& ctx);
  /// The equilibrium residual display of stress_kPa_ on preview_surface_ (remembered for the
  /// last two stresses).
  const std::vector<float>& surface_residual();
  void prepare(const FieldWorker::Context& ctx);
  /// Stage 1: the design fields. Sets `fields` (null when nothing is designed) and stress_kPa_;
  /// eigenvalue or equilibration failures go into `message` and leave the directions shown.
  const DesignResult* design_fields(const DesignState& design, nlohmann::json& message, nlohmann::json& timings);
  /// After an edit that failed validation (message["design_error"] says why): the designer's
  /// last valid design, which the designer kept, in stress_kPa_ and the message.
  const DesignResult* last_valid_design(nlohmann::json& message);
  /// Stage 2: the model cut by `requests`; reuses the previous cut model when `key` is unchanged.
  /// Returns true when the cut model was rebuilt.
  bool cut_model(const CutRequests& requests, const std::string& key, nlohmann::json& message);
  /// The statics of preview_model_ under stress_kPa_: with the kept factor once it is ready, with
  /// the kept multigrid until then (the factorization is started here, on a thread of its own).
  StaticResult solve_preview_statics(nlohmann::json& message);
  /// The wound opening over time (Newmark dynamics on the cut model), one "frame" message per step.
  void stream_opening(const DesignState& design, std::uint64_t generation, const FieldWorker::Context& ctx,
                      nlohmann::json& timings);

  // Worker-thread state (only the worker touches these).
  /// The session case's design settings (weights, equilibration, support; no strokes or points)
  /// and supports ("simulation"/"fixed"), read once; with the "simulation" support the design's
  /// held_vertices are those of the uncut model.
  StressDesign design_settings_;
  SimulationSettings simulation_;
  std::vector<VertexId> held_cut_;                    ///< held vertices of preview_model_ (the case's supports and the removed plugs)
  std::unique_ptr<BodySurface> body_surface_;         ///< of the uncut model
  std::vector<RoundIncision> preview_incisions_;      ///< the round-incision preview (paper fig. 5)
  std::unique_ptr<StressDesigner> designer_;
  /// Directions without magnitudes (strokes but no control point yet): the Langer interpolation
  /// and the surface normals (normal_axes of the interpolated normal field), built on first use.
  std::unique_ptr<LineFieldInterpolator> langer_only_;
  std::vector<Vec3> normal_axes_;
  DesignResult directions_only_;
  SparseMatrix divergence_;                           ///< T of the uncut model, for the residual display
  /// The residual display of the last two stresses on preview_surface_ (cleared with it).
  RecentResults<std::vector<Vec6>, std::vector<float>> surface_residuals_{2};
  std::string cut_key_;                               ///< what preview_model_ was cut with
  /// Names preview_surface_ in the messages ("surface"/"id"): this server's random token and a
  /// count of the surfaces built, so a page never takes another server's triangles for these.
  std::string surface_id_;
  std::uint64_t surfaces_built_ = 0;
  CutPlan plan_;
  std::vector<Vec6> stress_kPa_;                      ///< of the last design (per cell), for exports
  std::vector<Vec3> displacement_mm_;                 ///< of the last preview (per vertex of preview_model_)
  std::shared_ptr<TissueModel> preview_model_;        ///< the model cut by the preview and the user's cuts
  std::unique_ptr<RenderSurface> preview_surface_;
  std::vector<IncisionMargins> incision_margins_;    ///< per plan_.incisions: sampled on preview_model_'s surface
  CutFaceLayout cut_face_layout_;                     ///< cut faces of preview_model_ on preview_surface_, with their depth
  /// Statics of preview_model_ (stiffness, supports and CHOLMOD factor kept while the cuts do not
  /// change, so a design edit re-solves without refactoring); reset before preview_model_ changes.
  std::unique_ptr<StaticSolver> preview_statics_;
  /// A new cut model is first solved by the multigrid (preview_multigrid_: 2 s at 45k cells, where
  /// CHOLMOD's factorization takes 5-10 s) while the factor is made on a thread of its own
  /// (pending_statics_); an edit takes the factor once it is ready, the multigrid until then.
  std::unique_ptr<StaticSolver> preview_multigrid_;
  std::future<std::unique_ptr<StaticSolver>> pending_statics_;
  std::string factor_failed_;  ///< why the factorization for this cut model failed; empty: it did not
  /// Factorizations for cut models that were replaced before they finished (their threads hold
  /// the old model): dropped once done, waited for at destruction.
  std::vector<std::future<std::unique_ptr<StaticSolver>>> abandoned_statics_;

  const StudioSession& session_;
  Send send_;
  /// What the latest result exports (shared with the I/O thread under latest_mutex_).
  struct ExportSnapshot {
    std::shared_ptr<const TissueModel> model;  ///< cut
    std::vector<Vec3> displacement_mm;         ///< per vertex of model; empty = at rest
    std::vector<Vec6> stress_kPa;              ///< per cell; empty = none designed
    SurfaceMesh mesh;                          ///< deformed render surface
  };
  std::uint64_t results_published_ = 0;  ///< worker thread
  std::string broadcast_surface_id_;     ///< worker thread: the surface whose triangles the clients last got
  std::string server_token_;             ///< random, per StudioCompute
  mutable std::mutex latest_mutex_;
  nlohmann::json latest_result_;  ///< in full (with its triangles); dumped for each new client
  ExportSnapshot latest_export_;
  std::unique_ptr<FieldWorker> worker_;
};

}  // namespace cleave::studio
