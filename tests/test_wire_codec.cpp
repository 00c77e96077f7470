// The wire codec (proto/wire_codec.hpp): every option of an EvaluationRequest survives the wire, "the
// exact model only" has one encoding each way, a field the client did not set leaves the server's
// default, and a bad field is named.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/units.hpp"
#include "client/friction_client.hpp"
#include "proto/wire_codec.hpp"

namespace mufric {
namespace {

EvaluationRequest round_trip(const EvaluationRequest& what) {
  v1::EvaluateRequest wire;
  wire::encode_options(what, wire);
  EvaluationRequest back;
  EXPECT_EQ(wire::decode_options(wire, back), "");
  return back;
}

TEST(WireCodec, EveryOptionSurvivesTheWire) {
  const EvaluationRequest what{.std = true, .ci_level = 0.9, .gradient = true, .patch_std = true,
                               .mu_tolerance = 3e-5, .std_relative_tolerance = 2e-3,
                               .extrapolation = Extrapolation::refuse};
  const EvaluationRequest back = round_trip(what);
  EXPECT_EQ(back.std, what.std);
  EXPECT_EQ(back.ci_level, what.ci_level);
  EXPECT_EQ(back.gradient, what.gradient);
  EXPECT_EQ(back.patch_std, what.patch_std);
  EXPECT_EQ(back.mu_tolerance, what.mu_tolerance);
  EXPECT_EQ(back.std_relative_tolerance, what.std_relative_tolerance);
  EXPECT_EQ(back.extrapolation, what.extrapolation);
  EXPECT_EQ(round_trip(EvaluationRequest{}).extrapolation, Extrapolation::model_default);
}

TEST(WireCodec, TheExactModelHasOneEncodingEachWay) {
  for (const auto& [mu, sd] : {std::pair{0.0, 1e-3}, std::pair{1e-6, 0.0}, std::pair{0.0, 0.0}}) {
    const EvaluationRequest exact{.mu_tolerance = mu, .std_relative_tolerance = sd};
    v1::EvaluateRequest wire;
    wire::encode_options(exact, wire);
    EXPECT_LT(wire.mu_tolerance(), 0.0);
    EXPECT_LT(wire.std_tolerance(), 0.0);
    const EvaluationRequest back = round_trip(exact);
    EXPECT_EQ(back.mu_tolerance, 0.0);
    EXPECT_EQ(back.std_relative_tolerance, 0.0);
  }
}

TEST(WireCodec, FieldsAClientDidNotSetLeaveTheDefaults) {
  EvaluationRequest back;
  ASSERT_EQ(wire::decode_options(v1::EvaluateRequest{}, back), "");
  const EvaluationRequest defaults;
  EXPECT_EQ(back.mu_tolerance, defaults.mu_tolerance);
  EXPECT_EQ(back.std_relative_tolerance, defaults.std_relative_tolerance);
  EXPECT_FALSE(back.std);
  EXPECT_EQ(back.ci_level, 0.0);
}

TEST(WireCodec, ABadFieldIsNamed) {
  EvaluationRequest back;
  v1::EvaluateRequest wire;
  wire.set_ci_level(1.5);
  EXPECT_NE(wire::decode_options(wire, back).find("field ci_level"), std::string::npos);
  wire = {};
  wire.set_extrapolation(static_cast<v1::Extrapolation>(42));
  EXPECT_NE(wire::decode_options(wire, back).find("field extrapolation: unknown value 42"), std::string::npos);
  wire = {};
  wire.set_mu_tolerance(std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(wire::decode_options(wire, back).find("mu_tolerance"), std::string::npos);
}

// Every input the one table says is on the wire has its array there and its field in the client's
// block, and one that is not has neither; the two wire accessors agree.
TEST(WireCodec, EveryKnownInputOnTheWireHasItsArrayAndItsClientField) {
  v1::EvaluateRequest wire;
  double value = 1.0;
  std::vector<std::string> carried;
  for (const KnownInput& input : known_inputs()) {
    auto* array = wire::mutable_input_array(wire, input.name);
    EXPECT_EQ(array != nullptr, input.on_the_wire) << input.name;
    EXPECT_EQ(client::Block::field_for(input.name) != nullptr, input.on_the_wire) << input.name;
    if (array == nullptr) continue;
    array->Add(value);
    value += 1.0;
    carried.emplace_back(input.name);
  }
  ASSERT_GE(carried.size(), 4U);
  value = 1.0;
  for (const std::string& name : carried) {
    ASSERT_EQ(wire::input_array(wire, name)->size(), 1) << name;
    EXPECT_EQ(wire::input_array(wire, name)->Get(0), value) << name;
    value += 1.0;
  }
  EXPECT_EQ(wire::input_array(wire, "pressure"), nullptr);
  EXPECT_EQ(client::Block::field_for("pressure"), nullptr);
}

}  // namespace
}  // namespace mufric
