/// \file avatar.hpp
/// The convenience pipeline apps share: measurements (optionally mapped real -> virtual) ->
/// regressor -> betas -> rest-pose body -> achieved measurements and plausibility.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "caliper/mapping.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/regressor.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// Result of create_avatar().
struct Avatar {
  Eigen::VectorXd betas;  ///< model.num_betas() values (zeros beyond the regressor's outputs)
  /// Posterior covariance of the regressor's betas (noise-aware regressor only).
  std::optional<Eigen::MatrixXd> covariance;
  MeasurementMap input;       ///< the inputs as given
  MeasurementMap mapped;      ///< the inputs after the mapping (equal to input without mapping)
  MeasurementMap achieved;    ///< measure_all() of the avatar (13 + volume + weight + circumf.)
  Plausibility plausibility;  ///< of the regressor's betas
  std::vector<ValidationMessage> messages;  ///< validate_measurements(input)
  smpl::Vertices vertices;                  ///< rest-pose vertices of the avatar
};

/// Options of create_avatar().
struct AvatarOptions {
  const MeasurementMapping* mapping = nullptr;  ///< applied to the inputs first, if given
  bool circumferences = true;                   ///< in `achieved`
  bool refuse_invalid = true;  ///< throw InvalidInputError when validation finds an Error
};

/// Avatar from a plain regressor. Checks the regressor against the model (ModelMismatchError),
/// validates the inputs (InvalidInputError listing every Error message when refuse_invalid),
/// and throws InvalidInputError naming a missing input.
Avatar create_avatar(const smpl::BodyModel& model, const LinearRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options = {});

/// Avatar from the noise-aware regressor (any subset of its inputs; covariance filled).
Avatar create_avatar(const smpl::BodyModel& model, const NoiseAwareRegressor& regressor,
                     const MeasurementMap& measurements, const AvatarOptions& options = {},
                     const NoiseLevels& noise = {});

}  // namespace caliper
