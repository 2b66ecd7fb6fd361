// The convenience pipeline: measurements -> (mapping) -> regressor -> avatar and its report.
#include "caliper/avatar.hpp"

#include <string>

#include "caliper/errors.hpp"

namespace caliper {

namespace {

MeasurementMap prepare(const MeasurementMap& input, const AvatarOptions& options,
                       std::vector<ValidationMessage>& messages) {
  messages = validate_measurements(input);
  if (options.refuse_invalid && has_errors(messages)) {
    std::string text = "the measurements are not plausible:";
    for (const auto& m : messages) {
      if (m.severity == Severity::Error) text += "\n  " + m.message;
    }
    throw InvalidInputError(text);
  }
  return options.mapping ? options.mapping->apply(input) : input;
}

void finish(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
            const AvatarOptions& options, Avatar& a) {
  a.betas = Eigen::VectorXd::Zero(model.num_betas());
  a.betas.head(betas.size()) = betas;
  a.plausibility = plausibility(betas);
  a.vertices = shaped_vertices(model, a.betas);
  MeasureOptions mo;
  mo.circumferences = options.circumferences;
  a.achieved = measure_all(model, a.vertices, mo);
}

}  // namespace

Avatar create_avatar(const smpl::BodyModel& model, const LinearRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options) {
  regressor.signature().check(model);
  Avatar a;
  a.input = measurements;
  a.mapped = prepare(measurements, options, a.messages);
  finish(model, regressor.predict(a.mapped), options, a);
  return a;
}

Avatar create_avatar(const smpl::BodyModel& model, const NoiseAwareRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options,
                     const NoiseLevels& noise) {
  regressor.signature().check(model);
  Avatar a;
  a.input = measurements;
  a.mapped = prepare(measurements, options, a.messages);
  const Posterior post = regressor.predict(a.mapped, noise);
  a.covariance = post.covariance;
  finish(model, post.mean, options, a);
  return a;
}

}  // namespace caliper
