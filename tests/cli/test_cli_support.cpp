// Tests of the command line's own pieces: units, argument parser, CSV, people and ANSUR files,
// the default regressor rule.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "app/cli_style.hpp"
#include "cli_support.hpp"
#include "inputs.hpp"
#include "model_source.hpp"

namespace caliper::cli {
namespace {

// Unit conversions are exact decimal scalings; 1e-12 m allows for the last bit of rounding.
constexpr double kExact = 1e-12;

std::string temp_file(const std::string& name, const std::string& content) {
  const auto dir = std::filesystem::path(CALIPER_TEST_DATA_DIR) / "cli-unit";
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary) << content;
  return path.string();
}

TEST(Units, LengthsInEveryUnit) {
  EXPECT_NEAR(parse_length("168cm", "--height"), 1.68, kExact);
  EXPECT_NEAR(parse_length("168 cm", "--height"), 1.68, kExact);
  EXPECT_NEAR(parse_length("1.68m", "--height"), 1.68, kExact);
  EXPECT_NEAR(parse_length("1680mm", "--height"), 1.68, kExact);
  EXPECT_NEAR(parse_length("66in", "--height"), 66 * 0.0254, kExact);
  EXPECT_NEAR(parse_length("5ft6in", "--height"), 66 * 0.0254, kExact);
  EXPECT_NEAR(parse_length("5'6\"", "--height"), 66 * 0.0254, kExact);
  EXPECT_NEAR(parse_length("1.68M", "--height"), 1.68, kExact);
}

TEST(Units, MassesInEveryUnit) {
  EXPECT_NEAR(parse_mass("62kg", "--weight"), 62.0, kExact);
  EXPECT_NEAR(parse_mass("137lb", "--weight"), 137 * 0.45359237, kExact);
  EXPECT_NEAR(parse_mass("137 lbs", "--weight"), 137 * 0.45359237, kExact);
  EXPECT_NEAR(parse_mass("62000g", "--weight"), 62.0, kExact);
}

TEST(Units, BadValuesNameTheOptionAndWhatToDo) {
  try {
    parse_length("168", "--height");
    FAIL() << "a value without unit was accepted";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--height '168': no unit given"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("168cm"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_length("168kg", "--height"), UsageError);
  EXPECT_THROW(parse_length("abc", "--height"), UsageError);
  EXPECT_THROW(parse_length("nancm", "--height"), UsageError);
  EXPECT_THROW(parse_length("infm", "--height"), UsageError);
  EXPECT_THROW(parse_length("", "--height"), UsageError);
  EXPECT_THROW(parse_length("1m70cm", "--height"), UsageError);  // only ft + in combine
  EXPECT_THROW(parse_mass("62cm", "--weight"), UsageError);
  EXPECT_THROW(parse_mass("62", "--weight"), UsageError);
}

const std::vector<OptionSpec> kSpecs = {
    {"height", "", "LENGTH", "h", false},
    {"json", "", "", "j", false},
    {"jobs", "j", "N", "n", false},
    {"ansur", "", "FILE", "a", true},
};

TEST(Args, LongShortInlineAndPositional) {
  const ParsedArgs a = parse_args({"--height", "1.7m", "--json", "-j4", "file.csv", "--ansur=a.csv",
                                   "--ansur", "b.csv", "--", "--literal"},
                                  kSpecs);
  EXPECT_EQ(a.get("height").value(), "1.7m");
  EXPECT_TRUE(a.flags.count("json"));
  EXPECT_EQ(a.get("jobs").value(), "4");
  ASSERT_EQ(a.values.at("ansur").size(), 2u);
  EXPECT_EQ(a.values.at("ansur")[1], "b.csv");
  ASSERT_EQ(a.positional.size(), 2u);
  EXPECT_EQ(a.positional[1], "--literal");
}

TEST(Args, NegativeNumbersArePositionalValues) {
  const ParsedArgs a = parse_args({"--height", "-5kg", "-1"}, kSpecs);
  EXPECT_EQ(a.get("height").value(), "-5kg");
  ASSERT_EQ(a.positional.size(), 1u);
}

TEST(Args, ErrorsNameTheOption) {
  try {
    parse_args({"--heigth", "1m"}, kSpecs);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "unknown option --heigth (did you mean --height?)");
  }
  EXPECT_THROW(parse_args({"--height"}, kSpecs), UsageError);    // missing value
  EXPECT_THROW(parse_args({"--json=yes"}, kSpecs), UsageError);  // flag with value
  EXPECT_THROW(parse_args({"--height", "1m", "--height", "2m"}, kSpecs), UsageError);
  EXPECT_TRUE(parse_args({"-h"}, kSpecs).flags.count("help"));
  EXPECT_THROW(parse_int("x", "jobs", 1, 8), UsageError);
  EXPECT_THROW(parse_int("9", "jobs", 1, 8), UsageError);
  EXPECT_EQ(parse_int("8", "jobs", 1, 8), 8);
  EXPECT_THROW(parse_number_list("1,,2", "--betas"), UsageError);
  EXPECT_EQ(parse_number_list("1, -0.5,2", "--betas").size(), 3u);
}

TEST(Args, ErrorsSayWhatWasWrong) {
  const auto message = [](const std::vector<std::string>& args) {
    try {
      parse_args(args, kSpecs);
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({"--height"}), "option --height needs a value (LENGTH)");
  EXPECT_EQ(message({"--json=yes"}), "option --json takes no value");
  EXPECT_EQ(message({"--height", "1m", "--height", "2m"}), "option --height given more than once");
  EXPECT_EQ(message({"-x"}), "unknown option -x");
}

TEST(Args, HelpIsWrittenByCli11InTheCommonStyle) {
  const app::HelpText help{{"caliper demo FILE [options]", "caliper demo --ansur FILE"},
                           "What the command does.",
                           "example:\n  caliper demo a.csv"};
  const ParsedArgs a = parse_args({"--json", "-h"}, kSpecs, help);
  ASSERT_TRUE(a.flags.count("help"));
  const std::string& h = a.help;
  EXPECT_EQ(h.rfind("usage: caliper demo FILE [options]\n       caliper demo --ansur FILE\n", 0),
            0u)
      << h;
  EXPECT_NE(h.find("What the command does."), std::string::npos) << h;
  EXPECT_NE(h.find("options:"), std::string::npos) << h;
  EXPECT_NE(h.find("-j,--jobs N"), std::string::npos) << h;
  EXPECT_NE(h.find("--height LENGTH"), std::string::npos) << h;
  EXPECT_NE(h.find("-h,--help"), std::string::npos) << h;
  EXPECT_LT(h.find("--height"), h.find("example:")) << "the footer comes last: " << h;
}

TEST(CliStyle, DefaultsAndUnitsAreShown) {
  CLI::App cli("", "demo");
  app::apply_style(cli, {{"demo [options]"}, "", ""});
  int population = 2000;
  double seconds = -1;
  app::add_value(cli, "--population", population, "N", "bodies in the population");
  app::add_value(cli, "--exit-after", seconds, "SECONDS", "quit after this time (default: never)");
  const std::string h = cli.help();
  EXPECT_NE(h.find("bodies in the population (default 2000)"), std::string::npos) << h;
  EXPECT_NE(h.find("quit after this time (default: never)"), std::string::npos) << h;
  EXPECT_EQ(h.find("(default -1)"), std::string::npos) << "a stated default is not repeated";
  EXPECT_THROW(app::parse_command_line(cli, {"--population", "many"}), app::CommandLineError);
  const app::CommandLine line = app::parse_command_line(cli, {"--population", "12", "x"});
  EXPECT_EQ(population, 12);
  ASSERT_EQ(line.positional.size(), 1u);
  EXPECT_THROW(app::no_positional(line), app::CommandLineError);
  EXPECT_EQ(app::usage_error_line("demo", "bad"), "demo: error: bad (see demo --help)\n");
}

// The CSV reader itself is libcaliper's: tests/caliper/test_csv.cpp.

TEST(People, HeaderUnitsAreConverted) {
  EXPECT_EQ(measurement_column("height_cm")->first, "height");
  EXPECT_NEAR(measurement_column("height_cm")->second, 0.01, kExact);
  EXPECT_EQ(measurement_column("arm_span_in")->first, "arm_span_fingertips");
  EXPECT_EQ(measurement_column("weight_lb")->first, "weight");
  EXPECT_FALSE(measurement_column("weight_cm"));  // a weight in cm is not a weight
  EXPECT_FALSE(measurement_column("height_kg"));
  EXPECT_FALSE(measurement_column("height"));  // no unit
  EXPECT_FALSE(measurement_column("shoe_size_cm"));

  const std::string path = temp_file(
      "people.csv",
      "id,sex,height_cm,weight_kg,inseam_mm\nann,F,168,62,780\nbob,male,180,abc,\ncy,x,170,70,\n");
  const auto people = read_people_csv(path);
  ASSERT_EQ(people.size(), 3u);
  EXPECT_EQ(people[0].id, "ann");
  EXPECT_EQ(people[0].sex, "female");
  EXPECT_NEAR(people[0].inputs.at("height"), 1.68, kExact);
  EXPECT_NEAR(people[0].inputs.at("inseam_height"), 0.78, kExact);
  EXPECT_TRUE(people[0].error.empty());
  EXPECT_NE(people[1].error.find("weight_kg 'abc' is not a number"), std::string::npos);
  EXPECT_FALSE(people[1].inputs.count("inseam_height"));  // empty cell: not given
  EXPECT_NE(people[2].error.find("sex 'x'"), std::string::npos);
  EXPECT_THROW(read_people_csv(temp_file("nomeas.csv", "id,shoe\n1,42\n")), RuntimeError);
}

TEST(Ansur, ColumnsAreMappedAndLatin1IsKept) {
  const std::string path =
      temp_file("ansur.csv",
                "subjectid,stature,weightkg,span,crotchheight,hipbreadth,acromionradialelength,"
                "radialestylionlength,chestcircumference,Gender,SubjectsBirthLocation\n"
                "10027,1776,815,1782,877,342,335,251,1074,Male,M\xE9tis\n");
  const auto people = read_ansur_csv(path);
  ASSERT_EQ(people.size(), 1u);
  const Person& p = people[0];
  EXPECT_EQ(p.id, "10027");
  EXPECT_EQ(p.sex, "male");
  EXPECT_NEAR(p.inputs.at("height"), 1.776, kExact);
  EXPECT_NEAR(p.inputs.at("weight"), 81.5, kExact);
  EXPECT_NEAR(p.inputs.at("arm_span_fingertips"), 1.782, kExact);
  EXPECT_NEAR(p.inputs.at("inseam_height"), 0.877, kExact);
  EXPECT_NEAR(p.inputs.at("hip_width"), 0.342, kExact);
  EXPECT_NEAR(p.inputs.at("arm_length"), 0.586, kExact);
  EXPECT_NEAR(p.extra.at("chestcircumference"), 1.074, kExact);
  EXPECT_THROW(read_ansur_csv(temp_file("notansur.csv", "a,b\n1,2\n")), RuntimeError);
}

TEST(Ansur, RealFilesReadWhenPresent) {
  const std::string dir = std::string(CALIPER_SOURCE_DIR) + "/../shared/data/ansur2/";
  if (!file_exists(dir + "ANSUR_II_MALE_Public.csv")) GTEST_SKIP() << "no ANSUR II files";
  EXPECT_EQ(read_ansur_csv(dir + "ANSUR_II_MALE_Public.csv").size(), 4082u);
  EXPECT_EQ(read_ansur_csv(dir + "ANSUR_II_FEMALE_Public.csv").size(), 1986u);
}

TEST(DefaultRegressor, FollowsTheGivenInputs) {
  EXPECT_EQ(default_regressor({{"height", 1.7}, {"weight", 60}}), "R2");
  EXPECT_EQ(
      default_regressor(
          {{"height", 1.7}, {"weight", 60}, {"arm_span_fingertips", 1.7}, {"inseam_height", 0.8}}),
      "R4");
  EXPECT_EQ(default_regressor({{"height", 1.7},
                               {"weight", 60},
                               {"arm_span_fingertips", 1.7},
                               {"inseam_height", 0.8},
                               {"hip_width", 0.35}}),
            "R5");
  EXPECT_EQ(default_regressor({{"height", 1.7},
                               {"weight", 60},
                               {"arm_span_fingertips", 1.7},
                               {"inseam_height", 0.8},
                               {"hip_width", 0.35},
                               {"arm_length", 0.58}}),
            "noise-aware");
  EXPECT_EQ(default_regressor({{"height", 1.7}}), "noise-aware");
  EXPECT_EQ(normalise_regressor_name("r5"), "R5");
  EXPECT_EQ(normalise_regressor_name("noise_aware"), "noise-aware");
  EXPECT_THROW(normalise_regressor_name("R3"), UsageError);
}

TEST(Sex, Normalised) {
  EXPECT_EQ(normalise_sex("F"), "female");
  EXPECT_EQ(normalise_sex(" Male "), "male");
  EXPECT_EQ(normalise_sex("neutral"), "neutral");
  EXPECT_EQ(normalise_sex(""), "");
  EXPECT_THROW(normalise_sex("robot"), UsageError);
}

}  // namespace
}  // namespace caliper::cli
