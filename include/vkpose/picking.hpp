#pragma once
// Bin picking on top of the detections: grasps defined on the object (a grasp file per object),
// copied by the object's symmetries, placed at each detection's pose, refused where the gripper
// would hit the bin, the scene in front of the part or another detection, and the detections
// ranked into a pick list. The frames are drawn in docs/picking.md.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vkpose/bank.hpp"
#include "vkpose/detection.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

/// The gripper's envelope in the gripper frame: +z is the approach direction (into the part),
/// the origin the tool centre point (where the part is held); the envelope reaches back from
/// there, z from -length to 0: a cylinder of `radius` about z, or a box `size_x` by `size_y`.
/// With fingers (finger_length > 0, for jaws), that shape is the palm, from -length to
/// -finger_length, and two fingers finger_thickness (along x) by finger_width (along y) reach
/// on from it to z = 0, just outside the grasp's opening on either side. Moving in and out
/// along z, the gripper sweeps this envelope back by the approach and retreat distances.
struct GripperShape {
  enum class Kind { Cylinder, Box };
  Kind kind = Kind::Cylinder;
  float radius = 0.02f;
  float size_x = 0.f, size_y = 0.f;
  float length = 0.15f;
  float finger_length = 0.f, finger_width = 0.02f, finger_thickness = 0.01f;
};

/// One way to hold the object.
struct Grasp {
  std::string name;
  int priority = 0;         ///< among a detection's valid grasps, the highest is offered first
  Pose pose;                ///< the gripper frame in the object frame (object_T_gripper), metres
  float approach_m = 0.1f;  ///< the gripper comes in along +z from this far back
  float retreat_m = 0.1f;   ///< and leaves with the part along -z this far
  float opening_m = 0.f;    ///< parallel jaws: their opening (0 for a suction cup)
  float suction_radius_m = 0.f;  ///< a suction cup's radius (0 for jaws)
  GripperShape gripper;
};

/// A grasp file: the object it is for (a bank's object name) and its grasps.
struct GraspSet {
  std::string object;
  std::vector<Grasp> grasps;
};

/// Reads a grasp file (docs/picking.md): {"object", "gripper": {...}, "grasps": [{"name",
/// "priority", "position_m" or "position_mm", "approach" (unit z), "x" (unit, perpendicular),
/// "approach_m", "retreat_m", "opening_m" | "suction_radius_m", "gripper" (overrides)}]}.
/// InputError naming the file and the grasp for a value that is missing, not a finite number,
/// a direction that is not unit length (within 1 %) or axes not perpendicular, a negative
/// distance or size, or no grasps.
GraspSet parseGrasps(const std::string& json, const std::string& source);
GraspSet loadGrasps(const std::string& path);

/// Copies of a grasp about a symmetric object's axis by default: every 2.5 degrees, since a
/// part beside a neighbour or a wall can leave a gap of a few degrees that 10-degree steps miss.
inline constexpr int kGraspSymmetrySteps = 144;

/// The colour agreement from which PickParams::colour_outline_allowance starts to grow. On 38
/// synthetic cup bins, of the detections past the outline gate, 18 of the 22 cylinders taken
/// for cups agreed under 0.8 and 1,059 of the 1,118 right cups 0.8 or more.
inline constexpr float kColourOutlineAllowanceFrom = 0.6f;

/// The grasp files' grasps for each bank (by index, in the banks' order), each expanded by its
/// object's symmetries (expandBySymmetry); banks without a file get none. InputError for a
/// file of an object no bank is for (the banks' objects named).
std::vector<std::vector<Grasp>> graspsForBanks(const std::vector<std::string>& files,
                                               const std::vector<TemplateBank>& banks,
                                               int symmetry_steps = kGraspSymmetrySteps);

/// Grasps for a part without a grasp file of its own: a suction cup (`suction_radius_m`, on a
/// gripper `gripper_radius_m` wide) on the middle of each face of the mesh's box, approaching
/// along the face's inward normal.
std::vector<Grasp> faceSuctionGrasps(const Mesh& mesh, float suction_radius_m = 0.008f,
                                     float gripper_radius_m = 0.012f);

/// The grasps and their copies under the object's symmetries: for a symmetric bank (trained
/// with --symmetric: continuous about its up axis through its centre) `steps` turns about that
/// axis, and each near-symmetry's turn. Copies keep their grasp's name. Every copy of a grasp
/// holds the part the same way, so a symmetric part is never refused for its arbitrary angle.
std::vector<Grasp> expandBySymmetry(const std::vector<Grasp>& grasps, const TemplateBank& bank, int steps = 36);

/// A box-shaped bin. Bin frame: origin at the centre of the inside floor, z up out of the bin,
/// x and y along its walls.
struct BinBox {
  Pose pose;  ///< the bin frame in the camera frame (camera_T_bin)
  Eigen::Vector3f inner = Eigen::Vector3f(0.4f, 0.3f, 0.15f);  ///< inside length x, width y, wall height z
  float wall_thickness_m = 0.01f;
};

/// {"R": 9 numbers (row-major) or "rotation", "t_m": 3 numbers, "inner_m": 3, "wall_thickness_m"}
/// (docs/picking.md); InputError naming the file for anything missing or not sensible.
BinBox parseBin(const std::string& json, const std::string& source);
BinBox loadBin(const std::string& path);
std::string binJson(const BinBox& bin);

enum class PickOrder { Combined, Height, Score, Visible };
/// "combined", "height", "score", "visible"; InputError otherwise.
PickOrder parsePickOrder(const std::string& name);
const char* pickOrderName(PickOrder order);

struct PickParams {
  PickOrder order = PickOrder::Combined;
  /// The direction the robot approaches along, camera frame, where the robot's axis is given.
  /// Otherwise straight down into the bin (against its floor's normal) when there is a bin,
  /// else the camera's viewing direction (approachAxis()).
  std::optional<Eigen::Vector3f> approach_axis;
  float max_tilt_deg = 45.f;  ///< grasps whose approach is tilted further from that axis are refused
  /// Scene points inside the swept gripper that refuse a grasp (fewer are noise).
  int min_blocking_points = 12;
  /// Scene points within this of the part's own surface are the part (the gripper holds it).
  float part_tolerance_m = 0.005f;
  float clearance_m = 0.02f;  ///< free space around a grasp counts up to this
  /// A grasp that passes nearer than this to another detection's surface hits it: a
  /// neighbour's pose is a few millimetres off (more where it is partly hidden). The scene's
  /// points need none: they are where the camera saw them.
  float neighbour_margin_m = 0.003f;
  int symmetry_steps = kGraspSymmetrySteps;  ///< copies of a grasp about a symmetric object's axis
  /// A detection whose outline lies on the image's edges less than this (its
  /// outline_on_edges) is not picked: a grasp needs a pose that sits on the part, and a
  /// look-alike of the part's size (a cylinder taken for a cup) strays from the edges where
  /// the shapes differ. 0: off; detections that did not measure it are not held back.
  float min_outline_on_edges = 0.5f;
  /// A detection whose colour agrees with its model's less than this (its colour_agreement,
  /// measured where the mesh has colours) is not picked: a solid cylinder of a pale colour taken
  /// for a white cup fits the depth and much of the outline. On 38 synthetic cup bins, of the
  /// detections past the outline gate, the right cups agreed 0.697-1.00 (1,118) and 11 of the 22
  /// cylinders taken for cups 0.50-0.677 (the others 0.71-0.85); the demo's parts 0.70-0.98.
  /// LM-O's scanned models on a real camera agree 0.33-0.82 where right, so a scan's picks are
  /// refused more often (a refused part is seen again after the next pick; lower it for such a
  /// model). 0: off; detections that did not measure it are not held back.
  float min_colour_agreement = 0.68f;
  /// The outline gate asks up to this much less (min_outline_on_edges - this) of a detection
  /// whose colour was measured and reached min_colour_agreement: the whole allowance at an
  /// agreement of 1, nothing at kColourOutlineAllowanceFrom, linear between. The better its
  /// colour tells the part from a look-alike of its size, the less the outline gate need do, and
  /// a part partly under others keeps less of its outline on the image's edges. Without colours
  /// (a bank from an STL) the gate stays whole: there it is all that keeps clutter cylinders out.
  float colour_outline_allowance = 0.25f;
};

/// A grasp placed at a detection.
struct PlacedGrasp {
  std::string name;
  int priority = 0;
  Pose pose;                      ///< camera_T_gripper
  Eigen::Vector3f approach_point = Eigen::Vector3f::Zero();  ///< where the gripper starts its approach (camera frame)
  Eigen::Vector3f retreat_point = Eigen::Vector3f::Zero();   ///< where it ends the retreat
  float tilt_deg = 0.f;           ///< its approach's angle from PickParams::approach_axis
  float clearance_m = 0.f;        ///< nearest obstacle to the swept gripper, up to PickParams::clearance_m
  float opening_m = 0.f, suction_radius_m = 0.f;
  Grasp source;                   ///< the grasp (or its symmetric copy) in the object frame, with its gripper
};

struct RefusedGrasp {
  std::string name;
  /// e.g. "hits the bin's wall (+x)", "approach tilted 62 degrees (at most 45)", "hits detection 2
  /// (obj_000001)" (detections numbered from 1, as the detection table and the overlay label them)
  std::string reason;
};

/// What became of one detection's grasps: the valid ones (one copy of each named grasp, the one
/// whose approach the combined rank values most; best first: priority, then tilt) and
/// each refused grasp with the reason of its least tilted copy.
struct DetectionGrasps {
  std::vector<PlacedGrasp> valid;
  std::vector<RefusedGrasp> refused;
};

/// A detection in the pick list, its first valid grasp and the terms of its rank (each 0..1).
struct Pick {
  int detection = 0;  ///< index into the detections
  PlacedGrasp grasp;
  float score = 0.f;    ///< the detection's score
  float visible = 0.f;  ///< share of its camera-facing surface that nothing hides
  float height = 0.f;   ///< its centre's height above the bin floor over the wall height (or nearness to the camera)
  float reach = 0.f;    ///< 1 - tilt / max tilt
  float free = 0.f;     ///< clearance / PickParams::clearance_m
  float rank = 0.f;     ///< what PickParams::order ranks by (combined: docs/picking.md)
};

struct PickPlan {
  std::vector<DetectionGrasps> detections;  ///< parallel to the detections
  std::vector<Pick> picks;                   ///< detections with a valid grasp, first pick first
};

/// Places each detection's grasps (grasps[bank], already expanded; none: the detection is not
/// picked), refuses those that would hit something, and orders the detections into a pick
/// list. depth_m: the frame's depth in metres (0: no reading); bin: its walls and floor, when
/// known.
PickPlan planPicks(const std::vector<Detection>& detections, const std::vector<TemplateBank>& banks,
                   const std::vector<std::vector<Grasp>>& grasps, const cv::Mat& depth_m, const Camera& camera,
                   const std::optional<BinBox>& bin, const PickParams& params);

/// The approach axis a plan measures tilts from (unit, camera frame): the given one, else into
/// the bin (a robot reaches down into it wherever the camera looks from), else the camera's
/// viewing direction. InputError for a given axis of zero length.
Eigen::Vector3f approachAxis(const PickParams& params, const std::optional<BinBox>& bin);

/// One instance of a scene whose truth is known (a synthetic frame's ground truth).
struct TruthInstance {
  int bank = -1;            ///< index into the banks: the object
  Pose pose;                ///< object-to-camera
  float visib_fract = 1.f;  ///< visible share of its silhouette (BOP scene_gt_info.json)
};

/// What a perfect detector would be offered: the plan for the true instances themselves (each a
/// detection of score 1 at its true pose) against the same depth, bin and grasps, keeping only
/// the picks of instances at least `min_visib` visible (the others stay obstacles). No pick in
/// it means nothing in the frame can be taken: every instance is buried, out of reach or
/// hemmed in, and "no pick" is then the right answer.
PickPlan truthPickPlan(const std::vector<TruthInstance>& truth, const std::vector<TemplateBank>& banks,
                       const std::vector<std::vector<Grasp>>& grasps, const cv::Mat& depth_m, const Camera& camera,
                       const std::optional<BinBox>& bin, const PickParams& params, float min_visib = 0.f);

/// Why the plan's first pick would fail in the true scene, empty when it would not: no pick;
/// its detection is not within `max_error` diameters of a true instance of its object (mean
/// distance of the model's surface points to the nearest of the instance's: ADI, which
/// symmetric parts need); or its gripper, swept in and out, hits the bin or another true
/// instance.
std::string firstPickProblem(const PickPlan& plan, const std::vector<Detection>& detections,
                             const std::vector<TemplateBank>& banks, const std::vector<TruthInstance>& truth,
                             const std::optional<BinBox>& bin, float max_error = 0.1f);

/// The plan as JSON: {"grasps": [per detection {"valid": [{"name", "priority", "R", "t",
/// "approach_point", "retreat_point", "tilt_deg", "clearance_m", "opening_m" or
/// "suction_radius_m"}], "refused": [{"name", "reason"}]}], "picks": [{"detection", "grasp",
/// "rank", "score", "visible", "height", "reach", "free"}]} (metres, camera frame; R row-major).
std::string pickPlanJson(const PickPlan& plan);

/// Draws the first `count` picks on a BGR image: each grasp's approach axis from its approach
/// point to the tool centre point, and its jaws (or suction cup), numbered in pick order, the
/// first in green.
void drawPicks(cv::Mat& bgr, const PickPlan& plan, const Camera& camera, int count = 3);

/// What a gripper at camera_T_gripper (moving in and out along its z by the grasp's approach and
/// retreat) would hit of the bin and of `obstacles` (point sets in the camera frame, e.g. the
/// other parts, named by `names`): the first such thing as a reason, empty when nothing.
std::string gripperCollision(const Grasp& grasp, const Pose& camera_T_gripper, const std::optional<BinBox>& bin,
                             const std::vector<std::vector<Eigen::Vector3f>>& obstacles,
                             const std::vector<std::string>& names);

}  // namespace vkpose
