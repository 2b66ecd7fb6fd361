/// \file makehuman_measures.hpp
/// The survey measurements the open model v2 is fitted on (fit_measures() ids), taken on a
/// T-posed body of the MakeHuman topology (issue 11). The paper's measurements, the weight from
/// the volume and the chest, waist (navel) and hip circumferences are the library's
/// (caliper::measure(), caliper::circumferences()); the others are defined here, each as a rule
/// on the T-posed average body of the sex found once, then followed on every body through the
/// topology's vertices (a landmark vertex gives a height or a plane):
/// - iliac_crest_height: the average body's lateral torso vertex at ANSUR II's mean iliocristale
///   height / stature (0.608), above the floor;
/// - waist_iliac_circumference: the torso's girth at the iliac crest (NHANES's and the WHO's
///   waist);
/// - neck_circumference: the narrowest girth of the neck below the jaw (slices from 2 cm under to
///   3 cm over the average body's narrowest neck level, which lies between the SMPL neck and head
///   joints; ANSUR II: just below the laryngeal prominence);
/// - thigh_circumference: ANSUR II's definition, at the lowest point of the gluteal furrow (the
///   average body's buttock fold: where the back of the leg turns from buttock to thigh), the left
///   thigh's girth; where the thighs touch, the tape closes along the body's midline plane;
/// - calf_circumference: the left calf's largest horizontal girth (the average body's level);
/// - ankle_circumference: the left leg's smallest horizontal girth between 3 cm above the ankle
///   joint and the calf (the average body's level; ANSUR II: the minimum above the malleoli);
/// - wrist_circumference: the girth of the left forearm's slice perpendicular to the T-posed arm
///   through the wrist landmark (ANSUR II: at the styloid processes);
/// - knee_height: the lateral vertex of the left knee at the SMPL knee joint above the floor
///   (ANSUR II's lateral femoral epicondyle height);
/// - arm_length: acromion to wrist with the arm hanging at the side (hanging_arm_length(): the
///   shoulder joint turned down, the wrist following by the template's skinning weights), ANSUR
///   II's acromion-radiale plus radiale-stylion length; without it the fit met the span with the
///   men's arms 6.5 % short and their hands long;
/// - hand_length: the left wrist landmark to the middle fingertip in the T-pose (ANSUR II: from
///   the wrist crease at the stylion to the tip of the middle finger);
/// - acromial_height: the left acromion (shoulder landmark) above the floor; with the arm's
///   length it places the hanging wrist (ANSUR II's wrist height);
/// - upper_leg_length: the left trochanterion's height over the lateral femoral epicondyle's
///   (ANSUR II's trochanterionheight minus lateralfemoralepicondyleheight, two bony landmarks;
///   NHANES's upper leg length is mapped onto it, makehuman_shape.hpp); the trochanterion is the
///   most lateral point of the average body's horizontal section through the left hip at ANSUR
///   II's mean trochanterion height over the crotch for the sex (0.0388 of the stature women,
///   0.0313 men), a point of a mesh edge.
/// Girths are tape measures: the perimeter of the convex hull of the slice.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/measurements.hpp"
#include "caliper/weight.hpp"
#include "smpl/body_model.hpp"

namespace modelgen::mh {

/// How many ids SurveyVertices::trochanterion holds (the resolution of its point on an edge).
inline constexpr int kTrochanterShares = 16;

/// The vertices that carry the rules above (indices into the topology's vertices).
struct SurveyVertices {
  int iliac_crest = -1;   ///< left lateral torso vertex at the iliac crest
  int neck_front = -1;    ///< front midline vertex of the neck at the neck girth's level
  int gluteal_fold = -1;  ///< back of the left leg at the buttock fold
  int calf_back = -1;     ///< back of the left calf at its largest girth
  int ankle_back = -1;    ///< back of the left ankle at its smallest girth
  int knee_lateral = -1;  ///< lateral vertex of the left knee at the knee joint
  /// The left trochanterion: the most lateral point of the hip's horizontal section at the
  /// trochanter's level, a point on a mesh edge (the lateral hip's vertices lie 2 cm apart in
  /// height; a vertex would miss the level by up to 1 cm), as a landmark the model file can
  /// carry (caliper::landmark_point(), the mean of its ids): kTrochanterShares ids, each of the
  /// edge's two vertices repeated in proportion to its share of the point, rounded to
  /// 1/kTrochanterShares (the level then within a thirty-second of the edge's height).
  std::vector<int> trochanterion;
  double midline_x = 0.0;  ///< the body's midline (mean x of the hip joints)
};

/// Finds the SurveyVertices on the T-posed body `t` (faces `f`, SMPL joint regressor
/// `j_regressor`, landmark table of caliper::landmarks_for) of `sex` ("female", "male", or
/// "neutral": the trochanterion's level is the sex's). Throws std::runtime_error naming the rule
/// when no vertex fits it.
SurveyVertices survey_vertices(const smpl::Vertices& t, const smpl::Faces& f,
                               const smpl::SparseMatrix& j_regressor,
                               const caliper::LandmarkTable& landmarks, const std::string& sex);

/// The skin's allowance in the open models' weight formula (m^3): open_model_weight_formula().
inline constexpr double kSkinVolumeAllowance = 0.004;

/// The weight formula of the open models of `sex` ("female", "male", "neutral"): the paper's
/// (caliper::weight_formula_for()) read on the skin's volume plus kSkinVolumeAllowance,
/// coefficient x (V + 4 L) + intercept. The paper's lines were fitted to SMPL registered to
/// CAESAR's scans (underwear, a cap, breathing), so at equal weight they ask for more volume than
/// a naked skin encloses: 64.3 L of a 62 kg woman (0.965 kg/L), where tissue at about 1.04 kg/L
/// plus the lungs' residual air is 61-63 L. With the arms' girth fitted, the volume the paper's
/// formula asks for has to go somewhere: into the women's trunks (navel waist +14 mm on the
/// ANSUR II women, 244 subjects left out); with 4 L every residual is as small as without the
/// arms (docs/models.md). The fit weighs its bodies with it and the models carry it, so that the
/// product weighs an avatar as the generator fitted it.
caliper::WeightFormula open_model_weight_formula(const std::string& sex);

/// The fit_measures() of bodies of one model and sex, in fit_measures() order (metres, kg); NaN
/// where a measurement cannot be taken on a body. The rules are placed once on `rest`, a T-posed
/// body of the sex on `tmpl`'s topology (its average: the fold under the buttock, say, lies
/// 16 mm under the crotch on MakeHuman's base mesh and 48 mm on its average woman); `tmpl`
/// supplies the faces, the joint regressor and the landmarks.
struct Measurer {
  Measurer(const smpl::BodyModel& tmpl, const smpl::Vertices& rest, const std::string& sex);
  Eigen::VectorXd operator()(const smpl::Vertices& v) const;

  const smpl::BodyModel& model;  ///< the template (joint regressor, weights for the hanging arm)
  const smpl::Faces& faces;
  caliper::LandmarkTable landmarks;
  caliper::WeightFormula formula;
  SurveyVertices at;
  smpl::Faces neck_faces;   ///< the faces of the neck region (the neck slices cut)
  smpl::Faces leg_faces;    ///< the faces below the crotch (the leg slices cut)
  smpl::Faces wrist_faces;  ///< the faces of the left forearm's end and hand
};

}  // namespace modelgen::mh
