/// \file errors.hpp
/// Typed exceptions of libcaliper. Every message names the value, key or file concerned and says
/// what to do. Expected "no answer" outcomes are data (result structs with flags), not exceptions.
#pragma once

#include <stdexcept>
#include <string>

namespace caliper {

/// Base class of every libcaliper exception (JsonError has its own hierarchy).
class CaliperError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A library call got an unusable value: NaN or infinity, a negative length, an empty or
/// wrongly sized array, an unknown measurement id, a missing required input.
class InvalidInputError : public CaliperError {
 public:
  using CaliperError::CaliperError;
};

/// A measurement needs a landmark that neither the model nor the built-in tables define.
class LandmarkError : public CaliperError {
 public:
  using CaliperError::CaliperError;
};

/// A fitted regressor or mapping does not belong to this model (name, gender, vertex count or
/// number of shape components differ), or a regressor file is malformed.
class ModelMismatchError : public CaliperError {
 public:
  using CaliperError::CaliperError;
};

/// Floor or pivot calibration samples are too few or degenerate (NaN, colinear, all rotations
/// equal).
class CalibrationError : public CaliperError {
 public:
  using CaliperError::CaliperError;
};

}  // namespace caliper
