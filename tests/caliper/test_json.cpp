// caliper::Json on nlohmann-json: round trips, exact doubles, the written number forms, errors
// that name line and column, and the limits a hostile text must not pass.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "caliper/json.hpp"

namespace {

using caliper::Json;
using caliper::JsonError;
using caliper::parse_json;

TEST(Json, ParsesNestedDocument) {
  const Json j = parse_json(R"({"a": [1, 2.5, -3e2], "b": {"c": "x\ny", "d": null, "e": true}})");
  EXPECT_EQ(j.at("a").as_numbers(), (std::vector<double>{1, 2.5, -300}));
  EXPECT_EQ(j.at("b").at("c").as_string(), "x\ny");
  EXPECT_TRUE(j.at("b").at("d").is_null());
  EXPECT_TRUE(j.at("b").at("e").as_bool());
}

TEST(Json, DoublesRoundTripExactly) {
  const std::vector<double> values = {0.1,    1.0 / 3.0,     -2.718281828459045,
                                      1e-300, 6.02214076e23, std::nextafter(1.0, 2.0)};
  const Json parsed = parse_json(Json(values).dump());
  EXPECT_EQ(parsed.as_numbers(), values);
}

TEST(Json, UnicodeEscapes) {
  EXPECT_EQ(parse_json(R"("M\u00e9tis \ud83d\ude00")").as_string(),
            "M\xC3\xA9tis \xF0\x9F\x98\x80");
  const Json s(std::string("tab\there \"q\" \x01"));
  EXPECT_EQ(parse_json(s.dump()).as_string(), s.as_string());
}

TEST(Json, ObjectKeepsInsertionOrderAndReplaces) {
  Json o = Json::object();
  o.set("z", 1);
  o.set("a", 2);
  o.set("z", 3);
  EXPECT_EQ(o.dump(), R"({"z":3,"a":2})");
}

TEST(Json, ErrorsNameLineAndColumn) {
  try {
    parse_json("{\n  \"a\": 1,\n  \"b\": [1, 2,, 3]\n}");
    FAIL() << "expected JsonError";
  } catch (const JsonError& e) {
    EXPECT_EQ(e.line, 3);
    EXPECT_EQ(e.column, 14);  // the second comma
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
}

TEST(Json, RefusesMalformedInput) {
  for (const char* bad : {"", "{", "[1 2]", "{\"a\" 1}", "nul", "01", "1.", "\"abc", "NaN", "[1] x",
                          "\"\\q\"", "{\"a\":1,}"}) {
    EXPECT_THROW(parse_json(bad), JsonError) << bad;
  }
}

TEST(Json, RefusesDeepNesting) {
  EXPECT_THROW(parse_json(std::string(10000, '[')), JsonError);
  // 257 levels (the top one and 256 below it) are read; the 258th opening bracket is refused,
  // and the error points at it.
  const std::string ok = std::string(257, '[') + std::string(257, ']');
  EXPECT_EQ(parse_json(ok).size(), 1u);
  try {
    parse_json("{\"a\":\n" + std::string(258, '[') + std::string(258, ']') + "}");
    FAIL() << "expected JsonError";
  } catch (const JsonError& e) {
    EXPECT_EQ(e.line, 2);
    EXPECT_EQ(e.column, 257);  // the '[' at depth 258 (the object is the first level)
    EXPECT_NE(std::string(e.what()).find("nesting deeper than 256 levels"), std::string::npos)
        << e.what();
  }
}

TEST(Json, RefusesNonFiniteNumbersAndBadUtf8) {
  for (const char* bad : {"1e400", "[-1e999]", "Infinity", "-Infinity", "[NaN]"}) {
    EXPECT_THROW(parse_json(bad), JsonError) << bad;
  }
  try {
    parse_json("[1, NaN]");
    FAIL() << "expected JsonError";
  } catch (const JsonError& e) {
    EXPECT_EQ(e.column, 5);
    EXPECT_NE(std::string(e.what()).find("NaN and Infinity are not valid JSON numbers"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(parse_json("\"caf\xE9\""), JsonError);  // Latin-1, not UTF-8
}

// The written forms: integers without a fraction, other doubles as the shortest text that reads
// back exactly, the sign of zero kept, invalid UTF-8 replaced so that the text stays JSON.
TEST(Json, WrittenNumberAndStringForms) {
  EXPECT_EQ(Json(std::vector<double>{3, -42, 1e14, 0.5, 0.1, -0.0}).dump(),
            "[3,-42,100000000000000,0.5,0.1,-0.0]");
  EXPECT_TRUE(std::signbit(parse_json(Json(-0.0).dump()).as_number()));
  const Json latin1(std::string("caf\xE9"));
  EXPECT_EQ(parse_json(latin1.dump()).as_string(), "caf\xEF\xBF\xBD");
  Json o = Json::object();
  o.set("a", Json(std::vector<double>{1, 2}));
  o.set("b", Json::object());
  EXPECT_EQ(o.dump(2), "{\n  \"a\": [\n    1,\n    2\n  ],\n  \"b\": {}\n}");
}

TEST(Json, TypedAccessErrorsSayWhatWasFound) {
  const Json j = parse_json(R"({"n": "seven"})");
  try {
    j.at("n").as_number();
    FAIL();
  } catch (const JsonError& e) {
    EXPECT_STREQ(e.what(), "expected a number, found a string");
  }
  EXPECT_THROW(j.at("missing"), JsonError);
  EXPECT_THROW(parse_json("2.5").as_int(), JsonError);
}

TEST(Json, DumpRefusesNaN) {
  EXPECT_THROW(Json(std::numeric_limits<double>::quiet_NaN()).dump(), JsonError);
}

// Issue 10: objects of many keys are read and built in linear time (the timing is in
// tests/bench/bench_json.cpp); here the behaviour that the key index must keep.
TEST(Json, ManyKeysKeepOrderLookupAndDuplicates) {
  constexpr int kKeys = 5000;  // well above the size from which objects keep a key index
  std::string text = "{";
  for (int i = 0; i < kKeys; ++i)
    text += (i ? ",\"k" : "\"k") + std::to_string(i) + "\":" + std::to_string(i);
  text += ",\"k17\":-1}";  // a duplicate key: the last value wins, in the first position
  const Json j = parse_json(text);
  ASSERT_EQ(j.size(), static_cast<size_t>(kKeys));
  for (int i = 0; i < kKeys; ++i)
    ASSERT_EQ(j.at("k" + std::to_string(i)).as_number(), i == 17 ? -1.0 : i) << i;
  EXPECT_EQ(j.find("k5000"), nullptr);
  EXPECT_EQ(j.as_object()[17].first, "k17");
  EXPECT_EQ(j.as_object()[kKeys - 1].first, "k" + std::to_string(kKeys - 1));
  EXPECT_EQ(parse_json(j.dump()).dump(), j.dump());
}

TEST(Json, CopiesOfLargeObjectsAreIndependent) {
  Json a = Json::object();
  for (int i = 0; i < 40; ++i) a.set("k" + std::to_string(i), i);
  Json b = a;
  b.set("k3", "changed");
  b.set("new", true);
  EXPECT_EQ(a.at("k3").as_number(), 3.0);
  EXPECT_EQ(a.find("new"), nullptr);
  EXPECT_EQ(b.at("k3").as_string(), "changed");
  EXPECT_TRUE(b.at("new").as_bool());
  Json c;
  c = b;
  b.set("k0", "b only");
  EXPECT_EQ(c.at("k0").as_number(), 0.0);
  const Json moved = std::move(c);
  EXPECT_TRUE(moved.at("new").as_bool());
  EXPECT_EQ(moved.size(), 41u);
}

}  // namespace
