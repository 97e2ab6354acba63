#include "gpilqg/experiments/model_slice_io.hpp"

#include <stdexcept>

namespace gpilqg {

void write_model_slice(Hdf5Writer& h5, const std::string& group, const ModelSlice& s, const SystemSignature& signature) {
  if (s.grid.size() == 0) return;
  std::vector<Quantity> inputs = signature.states;
  inputs.insert(inputs.end(), signature.controls.begin(), signature.controls.end());
  const auto n = static_cast<int>(signature.states.size());
  if (s.output < 0 || s.output >= n || s.input < 0 || s.input >= static_cast<int>(inputs.size()))
    throw std::invalid_argument("write_model_slice: output " + std::to_string(s.output) + " or input " +
                                std::to_string(s.input) + " is not one of system '" + signature.name + "'");
  const Quantity& output = signature.states[static_cast<std::size_t>(s.output)];
  const Quantity& input = inputs[static_cast<std::size_t>(s.input)];
  const std::string g = group + "/figure1";
  h5.write_vector(g + "/grid", s.grid);
  h5.write_vector(g + "/simulator", s.simulator);
  h5.write_vector(g + "/mean", s.mean);
  h5.write_vector(g + "/std", s.std);
  h5.write_vector(g + "/truth", s.truth);
  h5.write_vector(g + "/data_z", s.data_z);
  h5.write_vector(g + "/data_y", s.data_y);
  h5.write_vector(g + "/data_residual", s.data_residual);
  h5.write_vector(g + "/base", s.base);
  h5.write_vector(g + "/length_scales", s.length_scales);
  h5.attribute(g, "output", output.name);
  h5.attribute(g, "input", input.name);
  h5.attribute(g, "output_unit", output.unit);
  h5.attribute(g, "input_unit", input.unit);
}

}  // namespace gpilqg
