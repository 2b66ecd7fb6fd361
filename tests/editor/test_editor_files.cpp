// The editor's files without the editor: profiles round-trip and refuse bad files, session
// measurements from JSON and from journals, and the export metadata.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "app/editor_files.hpp"
#include "caliper/errors.hpp"
#include "caliper/journal.hpp"
#include "editor_test_entry.hpp"

namespace ca = caliper::app;
using caliper::test::editor_test_entry;

namespace {
std::string files_temp_path(const std::string& name) {
  return std::string(CALIPER_TEST_DATA_DIR) + "/editor_files_" + name;
}
std::string write(const std::string& name, const std::string& text) {
  std::string path = files_temp_path(name);
  std::ofstream(path) << text;
  return path;
}
ca::Document level_two() {
  ca::Document d;
  d.level = 2;
  d.values = {{"height", 1.75},
              {"weight", 70.5},
              {"inseam_height", 0.81},
              {"arm_span_fingertips", 1.77},
              {"hip_width", 0.33}};  // not an input at level 2
  return d;
}
}  // namespace

TEST(EditorFiles, ProfileRoundTripKeepsEveryEditableInputExactly) {
  const ca::Document d = level_two();
  const Eigen::VectorXd betas = Eigen::VectorXd::LinSpaced(4, -1.0, 1.0);
  const caliper::Json j =
      ca::profile_json(d, ca::UnitSystem::Imperial, &editor_test_entry(), betas);
  EXPECT_EQ(j.at("format").as_string(), "caliper-profile");
  EXPECT_EQ(j.at("sex").as_string(), "female");
  EXPECT_EQ(j.at("betas").as_array().size(), 4u);
  EXPECT_FALSE(j.at("measurements").contains("hip_width"));  // only the editable inputs
  const std::string path = files_temp_path("profile.json");
  caliper::write_json_file(path, j);

  const ca::Profile p = ca::read_profile(path, ca::Document{});
  EXPECT_EQ(p.document.level, 2);
  EXPECT_TRUE(p.document.hierarchical);
  EXPECT_EQ(p.units, ca::UnitSystem::Imperial);
  EXPECT_EQ(p.sex, "female");
  for (const std::string& id : ca::level_inputs(2))
    EXPECT_EQ(p.document.values.at(id), d.values.at(id)) << id;  // 17 significant digits
  EXPECT_EQ(p.document.values.count("hip_width"), 0u);
}

// The arm taken hanging is written only when it is (a reader without the field takes the arm
// out sideways, as before it), read back, and absent means out sideways whatever the base says.
TEST(EditorFiles, ProfileKeepsTheArmTakenHanging) {
  ca::Document d = level_two();
  d.level = 3;
  d.values["arm_length"] = 0.591;
  EXPECT_FALSE(ca::profile_json(d, ca::UnitSystem::Metric, nullptr, Eigen::VectorXd())
                   .contains("arm_taken_hanging"));
  EXPECT_EQ(ca::profile_json(d, ca::UnitSystem::Metric, nullptr, Eigen::VectorXd())
                .at("version")
                .as_int(),
            1);
  d.arm_taken_hanging = true;
  const caliper::Json j = ca::profile_json(d, ca::UnitSystem::Metric, nullptr, Eigen::VectorXd());
  EXPECT_TRUE(j.at("arm_taken_hanging").as_bool());
  EXPECT_EQ(j.at("version").as_int(), 2);  // an editor without the field refuses it
  EXPECT_DOUBLE_EQ(j.at("measurements").at("arm_length").as_number(), 0.591);  // as typed
  const std::string path = files_temp_path("profile_hanging.json");
  caliper::write_json_file(path, j);
  const ca::Profile p = ca::read_profile(path, ca::Document{});
  EXPECT_TRUE(p.document.arm_taken_hanging);
  EXPECT_EQ(p.document, d);

  ca::Document hanging_base;
  hanging_base.arm_taken_hanging = true;
  const std::string head = R"({"format": "caliper-profile", "version": 1, )";
  const std::string old =
      write("profile_old.json", head + R"("measurements": {"arm_length": 0.5}})");
  EXPECT_FALSE(ca::read_profile(old, hanging_base).document.arm_taken_hanging);
  const std::string off =
      write("profile_off.json", head + R"("arm_taken_hanging": false, "measurements": {}})");
  EXPECT_FALSE(ca::read_profile(off, hanging_base).document.arm_taken_hanging);
}

TEST(EditorFiles, AProfileWithoutAModelNamesNoSex) {
  const caliper::Json j =
      ca::profile_json(ca::Document{}, ca::UnitSystem::Metric, nullptr, Eigen::VectorXd());
  EXPECT_FALSE(j.contains("sex"));
  EXPECT_FALSE(j.contains("model"));
}

TEST(EditorFiles, BadProfilesAreRefusedNamingTheProblem) {
  const auto message = [](const std::string& path) -> std::string {
    try {
      ca::read_profile(path, ca::Document{});
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  const std::string head = R"({"format": "caliper-profile", "version": )";
  EXPECT_NE(message(write("other.json", R"({"format": "x", "version": 1})")).find("not a caliper"),
            std::string::npos);
  EXPECT_NE(message(write("v3.json", head + R"(3, "measurements": {}})")).find("version 3"),
            std::string::npos);
  EXPECT_NE(message(write("r9.json", head + R"(1, "regressor": "R9", "measurements": {}})"))
                .find("unknown regressor 'R9'"),
            std::string::npos);
  EXPECT_NE(message(write("l4.json", head + R"(1, "level": 4, "measurements": {}})")).find("level"),
            std::string::npos);
  EXPECT_NE(
      message(write("range.json", head + R"(1, "measurements": {"height": 17.5}})")).find("height"),
      std::string::npos);
  EXPECT_FALSE(message(write("cut.json", head)).empty());
  for (const char* bad : {R"("yes")", "1", "null"}) {
    const std::string m = message(write(
        "hanging.json", head + R"(1, "arm_taken_hanging": )" + bad + R"(, "measurements": {}})"));
    EXPECT_NE(m.find("\"arm_taken_hanging\" must be true or false, not " + std::string(bad)),
              std::string::npos)
        << m;
  }
  EXPECT_FALSE(message(files_temp_path("missing.json")).empty());
}

TEST(EditorFiles, SessionMeasurementsFromJsonObjectsAndArrays) {
  const caliper::MeasurementMap a = ca::read_session_measurements(
      write("session_a.json", R"({"measurements": {"height": 1.7, "weight": {"value": 65}}})"));
  EXPECT_DOUBLE_EQ(a.at("height"), 1.7);
  EXPECT_DOUBLE_EQ(a.at("weight"), 65.0);
  const caliper::MeasurementMap b = ca::read_session_measurements(write(
      "session_b.json", R"({"result": {"measurements": [{"id": "hip_width", "value": 0.34}]}})"));
  EXPECT_DOUBLE_EQ(b.at("hip_width"), 0.34);
  EXPECT_THROW(ca::read_session_measurements(files_temp_path("no_such_session.json")),
               caliper::InvalidInputError);
}

TEST(EditorFiles, SessionJournalsAverageTheTakesAfterTheLastRedo) {
  const std::string path = files_temp_path("session.jsonl");
  {
    caliper::JournalWriter w = caliper::JournalWriter::create(path, caliper::Json::object());
    caliper::JournalRecord r;
    r.type = "sample";
    r.step = "height";
    for (double v : {1.50, 1.70, 1.72}) {
      r.value = v;
      w.append(r);
      if (v == 1.50) {
        caliper::JournalRecord redo;
        redo.type = "redo";
        redo.step = "height";
        w.append(redo);
      }
    }
    r.type = "typed";
    r.step = "weight";
    r.value = 64.0;
    w.append(r);
  }
  const caliper::MeasurementMap m = ca::read_session_measurements(path);
  EXPECT_DOUBLE_EQ(m.at("height"), (1.70 + 1.72) / 2);  // 1.50 was redone
  EXPECT_DOUBLE_EQ(m.at("weight"), 64.0);
}

TEST(EditorFiles, SessionInputsRiseToTheLevelTheSessionProvides) {
  const caliper::MeasurementMap achieved = {{"height", 1.6},         {"weight", 60.0},
                                            {"inseam_height", 0.75}, {"arm_span_fingertips", 1.6},
                                            {"arm_length", 0.55},    {"hip_width", 0.3}};
  ca::Document base;
  base.values = {{"height", 1.6}, {"weight", 60.0}};
  const ca::SessionInputs s = ca::session_inputs(base,
                                                 {{"height", 1.8},
                                                  {"inseam_height", 0.85},
                                                  {"arm_span_fingertips", 1.82},
                                                  {"not_a_measurement", 3.0},
                                                  {"weight", 5000.0}},  // out of range: not used
                                                 achieved);
  EXPECT_EQ(s.used, 3);
  EXPECT_EQ(s.document.level, 2);
  EXPECT_DOUBLE_EQ(s.document.values.at("height"), 1.8);
  EXPECT_DOUBLE_EQ(s.document.values.at("weight"), 60.0);  // the base's typed value stays
  EXPECT_THROW(ca::session_inputs(base, {{"weight", 5000.0}}, achieved),
               caliper::InvalidInputError);
}

// A session's arm length was taken out sideways (the VR protocol): with one, the arm is no
// longer taken hanging; without one, the typed hanging arm and its convention stay.
TEST(EditorFiles, ASessionsArmLengthIsTakenOutSideways) {
  ca::Document base;
  base.level = 3;
  base.arm_taken_hanging = true;
  base.values = {{"height", 1.6},
                 {"weight", 60.0},
                 {"inseam_height", 0.75},
                 {"hip_width", 0.3},
                 {"arm_span_fingertips", 1.6},
                 {"arm_length", 0.6}};
  const ca::SessionInputs with_arm = ca::session_inputs(base, {{"arm_length", 0.52}}, {});
  EXPECT_FALSE(with_arm.document.arm_taken_hanging);
  EXPECT_DOUBLE_EQ(with_arm.document.values.at("arm_length"), 0.52);
  const ca::SessionInputs without = ca::session_inputs(base, {{"height", 1.7}}, {});
  EXPECT_TRUE(without.document.arm_taken_hanging);
  EXPECT_DOUBLE_EQ(without.document.values.at("arm_length"), 0.6);
}

TEST(EditorFiles, ExportMetadataNamesTheModelAndTheShape) {
  ca::AvatarView a;
  a.betas = Eigen::VectorXd::Zero(3);
  a.betas(0) = 0.5;
  a.achieved["height"] = 1.7;
  ca::Document d;
  d.regressor = ca::RegressorChoice::R4;
  const auto meta = ca::export_metadata(editor_test_entry(), d, a);
  EXPECT_EQ(meta.at("regressor"), "R4");
  EXPECT_EQ(meta.at("model"), "random-test");
  EXPECT_EQ(caliper::parse_json(meta.at("betas")).as_array().size(), 3u);
  EXPECT_DOUBLE_EQ(caliper::parse_json(meta.at("measurements")).at("height").as_number(), 1.7);
  EXPECT_EQ(meta.at("generator").rfind("caliper-editor ", 0), 0u);
  EXPECT_EQ(meta.count("open_model_sex"), 0u);  // not made by caliper-modelgen
  EXPECT_EQ(ca::export_extensions().front(), ca::export_formats().front().extension);
  EXPECT_EQ(ca::export_extensions().size(), ca::export_formats().size());
}
