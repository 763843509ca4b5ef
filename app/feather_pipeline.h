// What the `plume` command does with a feather groom: the emitter and the guide stems of every frame
// come from Pipeline (posed, carried, simulated or read from a guide cache, exactly as for hair);
// the coat is bound once; each frame grows every feather.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "feathers/coat.h"
#include "groom/groom_desc.h"
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
  /// The whole frame. Frames should be asked for in increasing order when stems are simulated.
  Frame produce(int frame);
  /// The coat grown on the rest emitter with the rest stems (the preview camera frames it).
  feathers::CoatFrame rest_frame() const;
  /// Per feather, its key in the groom's own layer order (key feathers' `layer`, `layers.map`,
  /// `front`, `rear`), whether or not the groom turns layering on: empty when the groom gives none.
  std::vector<feathers::LayerKey> layer_keys() const;
  /// Options for writing this groom's feathers (template names, the OBJ texture coordinates).
  io::FeatherWriteOptions write_options() const;

 private:
  GroomDesc groom_;
  std::unique_ptr<Pipeline> base_;
  std::unique_ptr<feathers::Coat> coat_;
  std::vector<float> layer_map_;  // the groom's feathers.layers.map, or empty
};

}  // namespace plume
