// What the `plume` command does with a feather groom: the emitter and the guide stems of every frame
// come from Pipeline (posed, carried, simulated or read from a guide cache, exactly as for hair);
// the coat is bound once; each frame grows every feather.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "feathers/coat.h"
#include "groom/groom_desc.h"
#include "io/feather_lifts.h"
#include "io/feather_writers.h"

namespace plume {

class FeatherPipeline {
 public:
  /// Loads the emitter, the stems (the groom's guides) and the follicles, and binds the coat.
  /// options.strand_count, when >= 0, replaces the follicle count (a proxy of the full coat: a
  /// smaller count keeps a subset of its feathers). Throws InputError for bad input, and before any
  /// work for a coat whose frame would not fit in the memory this run may use.
  FeatherPipeline(const GroomDesc &groom, const PipelineOptions &options);
  ~FeatherPipeline();

  const GroomDesc &groom() const { return groom_; }
  /// The emitter and the stems: posed_mesh(), guides_at(), check_frame_inputs().
  Pipeline &base() { return *base_; }
  const Pipeline &base() const { return *base_; }
  const feathers::Coat &coat() const { return *coat_; }

  struct Frame {
    int frame = 0;
    Mesh mesh;                     // the posed emitter
    StrandSet stems;               // the guide stems at this frame
    feathers::CoatFrame feathers;  // the grown coat
  };
  /// The whole frame. Frames should be asked for in increasing order: the skin pass and the layering
  /// pass start from the frame before (their warm starts, Coat::grow), carried from the last frame
  /// produced, or replayed from options.simulation_start (stateless there), or, with a guide cache,
  /// read from the cache's lifts file of the frame before (io/feather_lifts.h; none before the cache's
  /// first frame).
  Frame produce(int frame);
  /// What `frame` carries to the next, carried as produce() carries it: what plume simulate writes
  /// beside the guide cache. The skin pass alone, or, with layers, the whole coat (the layering pass
  /// needs the vanes).
  struct StateFrame {
    Mesh mesh;
    StrandSet stems;
    feathers::CoatState state;
  };
  StateFrame carried(int frame);
  /// Whether frames carry a state (the skin pass lifts feathers, or the coat has layers).
  bool carries() const;
  /// `state` of `frame` as its lifts file holds it (the coat's feather ids).
  io::FeatherLifts lifts_record(int frame, const feathers::CoatState &state) const;
  /// Pipeline::check_frame_inputs() over every frame the range reads: with a guide cache, also the
  /// lifts files of the frames before the range's; without one, the frames the skin pass replays
  /// from options.simulation_start. Throws InputError naming the file.
  void check_frame_inputs(const FrameRange &range) const;
  /// The coat grown on the rest emitter with the rest stems (the preview camera frames it).
  feathers::CoatFrame rest_frame() const;
  /// Per feather, its key in the groom's own layer order (key feathers' `layer`, `layers.map`,
  /// `front`, `rear`), whether or not the groom turns layering on: empty when the groom gives none.
  std::vector<feathers::LayerKey> layer_keys() const;
  /// The layer order the coat keeps (with layers on) or would keep (off): from the coat grown on the
  /// rest pose without the layering pass, with the groom's keys.
  feathers::LayerOrder layer_order() const;
  /// Options for writing this groom's feathers (template names, the OBJ texture coordinates).
  io::FeatherWriteOptions write_options() const;

 private:
  GroomDesc groom_;
  std::unique_ptr<Pipeline> base_;
  std::unique_ptr<feathers::Coat> coat_;
  std::vector<float> layer_map_;  // the groom's feathers.layers.map, or empty

  /// Whether the carried state comes from the guide cache's lifts files.
  bool cached() const;
  /// The lifts file of `frame` beside the guide cache, in coat order; none when neither it nor the
  /// guide cache's file of `frame` exists (before the cache's first frame). Throws InputError naming
  /// the file when it is missing beside a cache frame, malformed, of another frame, lacks a feather,
  /// or lacks the layering pass's state for a coat with layers.
  std::optional<feathers::CoatState> read_cached_state(int frame) const;
  /// The state at frame - 1 (null at a first frame), replaying the frames between the last one
  /// carried and `frame` when needed. Call before base_->guides_at(frame): a replay asks for earlier
  /// frames' stems.
  const feathers::CoatState *warm_start(int frame);
  /// The whole frame from `previous` (null: stateless), nothing carried.
  Frame produce_from(int frame, const feathers::CoatState *previous);
  /// What `frame` carries from `previous` (null: stateless), nothing carried.
  StateFrame carried_from(int frame, const feathers::CoatState *previous);

  PipelineOptions options_;
  feathers::CoatState state_;  // at state_frame_
  std::optional<int> state_frame_;
  feathers::CoatState cached_state_;  // read from the cache for the frame being produced
};

}  // namespace plume
