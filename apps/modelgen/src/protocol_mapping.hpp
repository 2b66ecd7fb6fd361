/// \file protocol_mapping.hpp
/// NHANES's upper arm length on ANSUR II's acromion-radiale scale, so that the generator can fit
/// the NHANES subjects on it (issue 11; docs/models.md, "NHANES's upper arm length").
///
/// NHANES's `BMXARML` (acromion to olecranon, elbow bent 90 degrees) has the landmarks and
/// posture of ANSUR II's `shoulderelbowlength`, but at equal stature and weight it reads about
/// 3 cm longer (a difference of measuring protocol, measured by tools/survey_protocols.py). The
/// mesh measures the acromion-radiale length of the hanging arm (validation.hpp,
/// hanging_upper_arm_length()), which ANSUR II measures too. The mapping, per sex, from the
/// surveys themselves:
/// 1. the protocol offset: NHANES's value minus ANSUR II's shoulder-elbow length predicted at
///    the person's stature and cube root of weight (least squares on ANSUR II), averaged over
///    the NHANES people with a BMI under `max_bmi` (ANSUR II has few people above 35);
/// 2. acromion-radiale = intercept + slope x shoulder-elbow, least squares on ANSUR II;
/// so an NHANES person's value becomes intercept + slope x (BMXARML - offset).
///
/// Step 1 alone (protocol_offset()) also maps ANSUR II's *flexed* biceps circumference onto
/// NHANES's relaxed mid-upper-arm circumference `BMXARMC`, which the mesh measures: at equal
/// stature and weight the relaxed girth is the smaller (about 5 mm for women, 21 mm for men),
/// so a soldier's relaxed girth is taken as flexed + offset; and NHANES's upper leg length
/// `BMXLEG` (inguinal crease to the kneecap's upper edge, seated) onto ANSUR II's trochanterion
/// height minus its lateral femoral epicondyle height (+0.3 mm women, +9.1 mm men), so an NHANES
/// person's upper leg is taken as BMXLEG - offset.
#pragma once

#include <Eigen/Core>

namespace modelgen {

/// Step 1 of one sex: NHANES's value minus the ANSUR II value predicted at the NHANES person's
/// stature and cube root of weight, averaged over the people under the BMI cut (metres).
struct ProtocolOffset {
  double offset = 0.0;    ///< NHANES minus ANSUR II at equal stature and weight
  int nhanes_people = 0;  ///< behind the offset
};

/// Step 1 from `ansur` rows (stature m, weight kg, value m) and `nhanes` rows (height m, weight
/// kg, value m). Throws std::invalid_argument when a table has another number of columns, a
/// value is not a positive finite number, ANSUR II has fewer than 10 rows or no NHANES person is
/// under `max_bmi`.
ProtocolOffset protocol_offset(const Eigen::MatrixXd& ansur, const Eigen::MatrixXd& nhanes,
                               double max_bmi = 35.0);

/// One sex's mapping (metres).
struct UpperArmMapping {
  double offset = 0.0;       ///< NHANES minus ANSUR II's shoulder-elbow length (step 1)
  double intercept = 0.0;    ///< acromion-radiale = intercept + slope x shoulder-elbow (step 2)
  double slope = 0.0;        ///<
  double residual_sd = 0.0;  ///< of step 2's fit
  int nhanes_people = 0;     ///< behind the offset

  /// NHANES's upper arm length `bmxarml` (metres) as ANSUR II's acromion-radiale length.
  [[nodiscard]] double acromion_radiale(double bmxarml) const {
    return intercept + slope * (bmxarml - offset);
  }
};

/// The mapping of one sex from `ansur` rows (stature m, weight kg, shoulder-elbow length m,
/// acromion-radiale length m) and `nhanes` rows (height m, weight kg, upper arm length m).
/// Throws std::invalid_argument when a table has another number of columns, a value is not a
/// positive finite number, ANSUR II has fewer than 10 rows or no NHANES person is under
/// `max_bmi`.
UpperArmMapping upper_arm_mapping(const Eigen::MatrixXd& ansur, const Eigen::MatrixXd& nhanes,
                                  double max_bmi = 35.0);

}  // namespace modelgen
