#pragma once
// Two small hand-written robot descriptions in the generated-header format
// (docs/generated-model.md), used to test the model layer independently of
// the URDF generator: a floating 5-body tree (revolute, prismatic, continuous
// joints, rotated placements, general axes, full inertia tensors) and a
// fixed-base 5-body forest with two roots and world-fixed frames.

#include <array>
#include <limits>
#include <string_view>

#include "model/robot_description.hpp"

namespace hand_test {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
// Rotations (row-major) used below come from roll-pitch-yaw (0.3, -0.2, 0.5),
// (-0.4, 0.7, 0.1) and (1.0, 0.2, -0.6); oblique axes are (0.3, -0.5, 0.8)/|.| and (-0.6, 0, 0.8).

using hqp::model::BodyDesc;
using hqp::model::FrameDesc;
using hqp::model::JointType;

// Floating base: base -> link1 (revolute) -> link2 (prismatic); base -> link3 (continuous) ->
// link4.
struct FloatingTree {
  static constexpr const char* name = "hand_floating";
  static constexpr bool floating_base = true;
  static constexpr int nb = 5;
  static constexpr int nj = 4;
  static constexpr int nq = 11;
  static constexpr int nv = 10;
  static constexpr int nframes = 7;
  static constexpr double total_mass = 3.0 + 1.2 + 0.8 + 0.5 + 0.4;
  static constexpr std::array<BodyDesc, nb> bodies = {{
      {"base",
       "",
       JointType::Free,
       -1,
       0,
       0,
       {0, 0, 0},
       {1, 0, 0, 0, 1, 0, 0, 0, 1},
       {0, 0, 0},
       3.0,
       {0.05, -0.02, 0.1},
       {0.05, 0.06, 0.04, 0.002, -0.003, 0.001},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"link1",
       "j1",
       JointType::Revolute,
       0,
       7,
       6,
       {0.1, 0.2, -0.1},
       {0.86008933820504729, -0.50953628660839789, -0.024881779183339836, 0.46986894694951531,
        0.81023918587025623, -0.35033645881189418, 0.19866933079506122, 0.28962947762551555,
        0.93629336358419923},
       {0.30304576336566319, -0.5050762722761053, 0.80812203564176865},
       1.2,
       {0.0, 0.05, -0.15},
       {0.02, 0.018, 0.01, 0.001, 0.0005, -0.002},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"link2",
       "j2",
       JointType::Prismatic,
       1,
       8,
       7,
       {0.0, 0.05, -0.3},
       {0.76102116212842197, -0.34156954384626009, 0.55152247235209195, 0.07635680875224371,
        0.89141429791942461, 0.44671040644022703, -0.64421768723769102, -0.29784357670004791,
        0.70446630527559173},
       {-0.6, 0.0, 0.8},
       0.8,
       {0.02, -0.01, -0.1},
       {0.01, 0.012, 0.006, -0.0004, 0.0003, 0.0002},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"link3",
       "j3",
       JointType::Continuous,
       0,
       9,
       8,
       {-0.1, -0.2, 0.05},
       {0.8088838516750253, 0.44305268049765023, -0.38653749727965964, -0.55338721660408663,
        0.35153692542323844, -0.7551055413405191, -0.19866933079506122, 0.8246975884333746,
        0.52953223191191956},
       {1, 0, 0},
       0.5,
       {0.1, 0.0, 0.0},
       {0.003, 0.004, 0.005, 0, 0, 0},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"link4",
       "j4",
       JointType::Revolute,
       3,
       10,
       9,
       {0.2, 0.0, 0.0},
       {1, 0, 0, 0, 1, 0, 0, 0, 1},
       {0, 1, 0},
       0.4,
       {0.05, 0.01, 0.02},
       {0.002, 0.003, 0.0025, 0.0001, -0.0002, 0.00005},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
  }};
  static constexpr std::array<FrameDesc, nframes> frames = {{
      {"base", 0, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"link1", 1, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"link2", 2, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"link3", 3, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"link4", 4, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"tip",
       2,
       {0.05, -0.02, -0.2},
       {0.86008933820504729, -0.50953628660839789, -0.024881779183339836, 0.46986894694951531,
        0.81023918587025623, -0.35033645881189418, 0.19866933079506122, 0.28962947762551555,
        0.93629336358419923}},
      {"foot",
       4,
       {0.1, 0.0, -0.05},
       {0.8088838516750253, 0.44305268049765023, -0.38653749727965964, -0.55338721660408663,
        0.35153692542323844, -0.7551055413405191, -0.19866933079506122, 0.8246975884333746,
        0.52953223191191956}},
  }};
  static constexpr int frameIndex(std::string_view n) { return hqp::model::indexOf(frames, n); }
  static constexpr int bodyIndex(std::string_view n) { return hqp::model::indexOf(bodies, n); }
  struct Frames {
    static constexpr int base = 0, link1 = 1, link2 = 2, link3 = 3, link4 = 4, tip = 5, foot = 6;
  };
};

// Fixed base: world -> a1 -> a2 -> a3 (prismatic); world -> b1 (continuous) -> b2.
struct FixedForest {
  static constexpr const char* name = "hand_fixed";
  static constexpr bool floating_base = false;
  static constexpr int nb = 5;
  static constexpr int nj = 5;
  static constexpr int nq = 5;
  static constexpr int nv = 5;
  static constexpr int nframes = 8;
  static constexpr double total_mass = 1.0 + 0.9 + 0.6 + 1.1 + 0.7;
  static constexpr std::array<BodyDesc, nb> bodies = {{
      {"a1",
       "ja1",
       JointType::Revolute,
       -1,
       0,
       0,
       {0, 0, 0.2},
       {0.86008933820504729, -0.50953628660839789, -0.024881779183339836, 0.46986894694951531,
        0.81023918587025623, -0.35033645881189418, 0.19866933079506122, 0.28962947762551555,
        0.93629336358419923},
       {0, 0, 1},
       1.0,
       {0.02, 0.01, 0.1},
       {0.01, 0.012, 0.008, 0.0005, -0.0003, 0.0002},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"a2",
       "ja2",
       JointType::Revolute,
       0,
       1,
       1,
       {0.0, 0.1, 0.3},
       {1, 0, 0, 0, 1, 0, 0, 0, 1},
       {0.30304576336566319, -0.5050762722761053, 0.80812203564176865},
       0.9,
       {0.1, -0.02, 0.03},
       {0.004, 0.009, 0.007, -0.0006, 0.0004, 0.0003},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"a3",
       "ja3",
       JointType::Prismatic,
       1,
       2,
       2,
       {0.2, 0.0, 0.0},
       {0.8088838516750253, 0.44305268049765023, -0.38653749727965964, -0.55338721660408663,
        0.35153692542323844, -0.7551055413405191, -0.19866933079506122, 0.8246975884333746,
        0.52953223191191956},
       {1, 0, 0},
       0.6,
       {0.05, 0.0, -0.02},
       {0.002, 0.003, 0.0035, 0.0001, 0.0, -0.0002},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"b1",
       "jb1",
       JointType::Continuous,
       -1,
       3,
       3,
       {0.5, 0.0, 0.0},
       {0.76102116212842197, -0.34156954384626009, 0.55152247235209195, 0.07635680875224371,
        0.89141429791942461, 0.44671040644022703, -0.64421768723769102, -0.29784357670004791,
        0.70446630527559173},
       {0, 1, 0},
       1.1,
       {0.0, 0.1, 0.05},
       {0.02, 0.01, 0.015, 0.001, 0.002, -0.001},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
      {"b2",
       "jb2",
       JointType::Revolute,
       3,
       4,
       4,
       {0.0, 0.0, 0.25},
       {1, 0, 0, 0, 1, 0, 0, 0, 1},
       {-0.6, 0.0, 0.8},
       0.7,
       {-0.03, 0.02, 0.12},
       {0.006, 0.005, 0.004, 0.0002, -0.0001, 0.0003},
       -kInf,
       kInf,
       kInf,
       kInf,
       0.0,
       0.0},
  }};
  static constexpr std::array<FrameDesc, nframes> frames = {{
      {"ground", -1, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"mount",
       -1,
       {0.1, 0.2, 0.3},
       {0.76102116212842197, -0.34156954384626009, 0.55152247235209195, 0.07635680875224371,
        0.89141429791942461, 0.44671040644022703, -0.64421768723769102, -0.29784357670004791,
        0.70446630527559173}},
      {"a1", 0, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"a2", 1, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"a3", 2, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"b1", 3, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"b2", 4, {0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}},
      {"tool",
       2,
       {0.1, 0.05, -0.02},
       {0.86008933820504729, -0.50953628660839789, -0.024881779183339836, 0.46986894694951531,
        0.81023918587025623, -0.35033645881189418, 0.19866933079506122, 0.28962947762551555,
        0.93629336358419923}},
  }};
  static constexpr int frameIndex(std::string_view n) { return hqp::model::indexOf(frames, n); }
  static constexpr int bodyIndex(std::string_view n) { return hqp::model::indexOf(bodies, n); }
};

}  // namespace hand_test
