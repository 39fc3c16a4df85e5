#pragma once
// Training (stage 0) and the template bank: training views on a (hemi)sphere, templates
// rendered from a mesh with their LINEMOD features, the pose each was rendered at and the
// depth/normal crops the cluster score compares; the bank file that stores them, and a cache
// of banks kept between runs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "vkpose/config.hpp"
#include "vkpose/device.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

// ---- training views --------------------------------------------------------------------

/// An evenly stepped range, both ends included: from, from + step, ..., to.
struct SteppedRange {
  float from = 0.f, to = 0.f, step = 1.f;
  /// Index-based so that rounding never drops the last value or adds one past `to`. Inline:
  /// the matcher's depth gate (below training) reads the trained distances too.
  std::vector<float> values() const {
    if (step <= 0.f) return {from};
    std::vector<float> out;
    const int n = static_cast<int>(std::floor((to - from) / step + 1e-4f)) + 1;
    for (int i = 0; i < n; ++i) out.push_back(from + static_cast<float>(i) * step);
    return out;
  }
  /// The lower end, whichever way round the range was given (radii: the nearest distance
  /// trained, which the pile rules read).
  float low() const { return std::min(from, to); }
};

/// Parses "A:B:STEP" (or a single value "A"); throws InputError on nonsense.
SteppedRange parseSteppedRange(const std::string& text, const std::string& what);

/// How much nearer or farther than its training distance `d` a view still matches (LINEMOD
/// matches a view at about the size it was trained at): half the bank's distance step (0 for
/// a bank of one distance), at least 5 % of d. The matcher's depth gate and coveredDistances
/// both use it.
inline float trainedDistanceAllowance(float distance_step, float d) {
  return std::max(0.5f * distance_step, 0.05f * d);
}

/// The camera distances (metres, to the object's centre) a bank trained at `radii` finds an
/// object at: the nearest and farthest trained distance widened by trainedDistanceAllowance.
inline std::pair<float, float> coveredDistances(const SteppedRange& radii) {
  const std::vector<float> r = radii.values();
  const float step = r.size() > 1 ? radii.step : 0.f;
  return {r.front() - trainedDistanceAllowance(step, r.front()), r.back() + trainedDistanceAllowance(step, r.back())};
}

struct ViewSamplingParams {
  /// Viewpoints on the (hemi)sphere, spread by a Fibonacci lattice. Paper: 216.
  int viewpoints = 216;
  /// Upper hemisphere (object +z up, cameras above the object's centre) or the full sphere.
  bool full_sphere = false;
  /// Camera distances from the object's centre, metres. Paper: 0.6 to 1.0 m, 0.1 m apart.
  SteppedRange radii{0.6f, 1.0f, 0.1f};
  /// In-plane rotations about the optical axis, degrees. Paper: -60 to +60, 10 apart.
  SteppedRange inplane_deg{-60.f, 60.f, 10.f};
  /// Viewpoints within this angle (degrees) of their hemisphere's pole take in-plane rotations
  /// over the whole turn instead (fullTurnInPlane, at fullTurnStep about its middle). Seen
  /// from near its up axis, a part's turn in the image is its turn about that axis (in a bin,
  /// chance) and where in the image it lies under a camera looking down, not the camera's
  /// roll that inplane_deg bounds. 0: inplane_deg for every viewpoint (the paper's sampling).
  float full_turn_within_deg = 0.f;
  /// The object's up direction (object frame, unit): the (hemi)sphere is sampled about it and
  /// image "up" follows it, so templates show the object as it stands. `vkpose train` finds it
  /// (findUpAxis) unless --up names one; +z is the modelling convention.
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  /// The up directions of the object's other resting poses (lying on a side, upside down;
  /// object frame, unit): each adds a hemisphere of views about it, image up along it, so that
  /// an object tipped over is still seen by some template. `vkpose train` finds them
  /// (otherRestingUps) unless --resting up; none with the full sphere, which sees every side.
  std::vector<Eigen::Vector3f> other_ups;
};

/// The whole turn's step where --inplane is one angle (whose step says nothing), degrees.
inline constexpr float kFullTurnSingleAngleStepDeg = 10.f;
/// `inplane`'s step, or kFullTurnSingleAngleStepDeg where it holds one angle.
float fullTurnStep(const SteppedRange& inplane);
/// The in-plane rotations of a whole turn at fullTurnStep on `inplane`'s grid, from half a
/// turn below its middle (-60:60:10 gives -180 to 170, and -180:170:10 itself): what views
/// near a hemisphere's pole take (full_turn_within_deg).
std::vector<float> fullTurnInPlane(const SteppedRange& inplane);

/// Throws InputError when the counts or ranges are out of bounds (full_turn_within_deg outside
/// 0 to 90), `up` or one of `other_ups` is not a unit vector, there are more than five other
/// ups, or other ups come with the full sphere.
void validateViewSampling(const ViewSamplingParams& params);

// ---- the up axis -----------------------------------------------------------------------

/// "+x", "-x", "+y", "-y", "+z", "-z" as a unit vector; InputError otherwise.
Eigen::Vector3f parseUpAxis(const std::string& text);
/// The name of an axis-aligned unit vector ("-z"), or its components ("(0.000, 0.707, 0.707)").
std::string upAxisName(const Eigen::Vector3f& up);

/// How the object would rest with one axis up: on its broadest base within 15 degrees of it
/// (scanned meshes are not modelled exactly axis-aligned).
struct RestingCandidate {
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  /// Area of what touches the table (points within max(1 mm, 1.5 % of the height) of the
  /// lowest one), as a share of the object's footprint along `up`.
  float support = 0.f;
  float tilt_deg = 0.f;  ///< angle between the base's normal and `up`
  /// Distance of the centre of mass's projection inside that contact area, metres (negative:
  /// outside, the object tips over).
  float margin_m = 0.f;
  bool stands() const;  ///< stable on a broad enough base (support >= 0.15, margin > 0)
};

struct UpAxisChoice {
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  bool found = false;  ///< false: no axis gives a stable, broad base; +z is assumed
  std::vector<RestingCandidate> candidates;  ///< +z, -z, +y, -y, +x, -x
  std::string reason;  ///< one line for the user
};

/// The direction the object stands along, from its mesh: of the six axis directions, in the
/// order +z, -z, +y, -y, +x, -x (the modelling conventions, most common first), the first on
/// which the object stands (RestingCandidate::stands) on a base at least half as broad as the
/// broadest it stands on. Meshes are modelled axis-aligned, and a box-like object is stable on
/// several faces: the order keeps the modeller's +z where the object stands on it, the share
/// passes over a side it could lie on when its real base is elsewhere, and a mesh modelled
/// upside down (milk.stl: its cap at -z) is turned the right way up.
UpAxisChoice findUpAxis(const Mesh& mesh);

// ---- near-symmetries ------------------------------------------------------------------
// Rotations that map the object's surface onto itself within a tolerance, found from the mesh
// at training and stored in the bank. A pose and its symmetric alternatives fit the scene's
// depth about equally well, so after ICP the detector renders each and lets appearance
// (colour) decide (docs/pipeline.md, stages 0 and 8).

/// One near-symmetry: a rotation about an axis through `point` (object frame, metres).
struct NearSymmetry {
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();  ///< unit
  Eigen::Vector3f point = Eigen::Vector3f::Zero();  ///< on the axis
  float angle_deg = 0.f;
  /// How far the turned surface lies from the surface: the 90th percentile of its samples'
  /// distances to the nearest sample of the unturned surface, less the same figure for no turn
  /// (the sampling's own spacing), metres.
  float deviation_m = 0.f;

  /// The turn as an object-frame transform: x -> R (x - point) + point. A pose P of the
  /// object and P * transform() fit the same scene within deviation_m.
  Pose transform() const;
};

/// The near-symmetries of a mesh: turns by 60, 90, 120, 180, 240, 270 and 300 degrees about
/// each principal axis of its surface (through the surface's centroid) and about the model's
/// x, y and z axes through its bounding box's centre, kept when the surface maps onto itself
/// within `tolerance_m` (NearSymmetry::deviation_m). Sorted by deviation, at most `max_count`
/// (a rotationally symmetric object passes every turn). Deterministic. An empty mesh or a
/// tolerance <= 0 gives none.
std::vector<NearSymmetry> findNearSymmetries(const Mesh& mesh, float tolerance_m, int max_count = 7);

/// The near-symmetries (within 1 % of the diameter) that map the mesh onto itself: every
/// vertex turned lands within `tolerance_m` of a vertex of the same colour (within 0.1 a
/// channel). findNearSymmetries asks that of 90 % of the surface, which a cup's handle passes;
/// this asks it of all of it, shape and paint: a pose turned by one is the same picture, as
/// the spark-plug key's half-turn about its socket. BOP's `symmetries_discrete`, which synth
/// writes so that eval scores such an object with ADI. Meshes tessellated unevenly (scans)
/// find none.
std::vector<NearSymmetry> exactSymmetries(const Mesh& mesh, float tolerance_m);

/// Half-turns that nearly map the surface onto itself but not within the near-symmetry
/// tolerance: the ones detection may still confuse with the pose (a carton turned end for
/// end, 8 mm off; a jug turned flank for flank, 9 mm off). Half-turns about the same axes
/// as findNearSymmetries, kept when their deviation lies in (from_m, to_m]; sorted by
/// deviation, at most `max_count`. The detector refits each after ICP and lets depth (and
/// colour) choose (VerifyParams::look_alike_tolerance). Empty when to_m <= from_m.
std::vector<NearSymmetry> findLookAlikeTurns(const Mesh& mesh, float from_m, float to_m, int max_count = 3);

/// A body of revolution found in its near-symmetries, whether or not the bank was trained
/// `--symmetric` (a lidded cup): the first of them about an axis that has both a turn of a
/// sixth (60, 120, 240 or 300 degrees) and one of a quarter (90 or 270), so at least 12-fold.
/// None otherwise: a box passes only quarters, a hexagonal nut only sixths. Its axis and point
/// are the axis of revolution.
std::optional<NearSymmetry> revolutionAxis(const std::vector<NearSymmetry>& symmetries);

/// "180 deg about (0.00, 0.00, 1.00)" for messages.
std::string describe(const NearSymmetry& s);

/// The other poses the object rests in that training should also see (lying on a side, upside
/// down): the axes of `choice.candidates` on which it stands (RestingCandidate::stands), less
/// `up` and those that a near-symmetry turns into `up` or into one already kept (their views
/// look the same: a square carton lying on any of its four sides). In the candidates' order.
std::vector<Eigen::Vector3f> otherRestingUps(const UpAxisChoice& choice, const Eigen::Vector3f& up,
                                             const std::vector<NearSymmetry>& symmetries);

/// Training nearer than this (the nearest of --radii, metres) is a bin-picking cell's working
/// distance: whatever the part's size, it lies in a pile any way up (a 17 cm spark-plug key on
/// its side), so `--resting auto` trains every resting pose.
inline constexpr float kPileDistanceM = 0.5f;

/// What planTraining gives ViewSamplingParams::full_turn_within_deg by default for a part it
/// trains to lie in a bin (trainsOtherRestingPoses): a camera looking down sees parts within
/// its half field of view (29-36 degrees for a 640 x 480 image at f 572) plus a pile's tilt
/// of the up axis at any turn (on the metal piles every key that needed an in-plane turn past
/// 60 degrees was seen within 36 degrees of a pole; docs/history.md).
inline constexpr float kPileFullTurnWithinDeg = 40.f;

/// Whether training covers the other resting poses: `resting` is "all", "up" or "auto" (all for
/// a part smaller than kSmallPartDiameterM, config.hpp, or trained nearer than kPileDistanceM:
/// parts picked from bins lie any way up, while larger objects seen from farther mostly stand).
/// Throws InputError for anything else.
bool trainsOtherRestingPoses(const std::string& resting, float diameter_m, float nearest_distance_m);

/// One training view: the object-to-camera pose (x_cam = R x_obj + t) that puts `centre`
/// (in object coordinates) on the optical axis at `distance`.
struct TrainingView {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  float distance = 0.f;     ///< metres from the camera to the object's centre
  float inplane_deg = 0.f;  ///< in-plane rotation of this view
  int viewpoint = 0;        ///< index of the viewpoint on the sphere (other ups' hemispheres follow on)
  /// The up axis of the hemisphere the view is on (object frame): image up follows it.
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
};

/// Unit directions from the object's centre to the cameras: a Fibonacci lattice over the
/// upper hemisphere (z >= 0) or the whole sphere.
std::vector<Eigen::Vector3f> sphereViewpoints(int count, bool full_sphere);

/// A camera at `centre + distance * direction` looking at `centre`, image "up" along `up`
/// (the object's up axis) where possible (along the axis perpendicular to it that +y would
/// become, looking straight down it), then rotated in-plane by `inplane_deg`.
TrainingView lookAtView(const Eigen::Vector3f& direction, const Eigen::Vector3f& centre, float distance,
                        float inplane_deg, const Eigen::Vector3f& up = Eigen::Vector3f::UnitZ());

/// All views, viewpoint-major, then radius, then in-plane rotation; the (hemi)sphere's
/// viewpoints turned so that its pole is `params.up`, then those of a hemisphere about each of
/// `params.other_ups`.
std::vector<TrainingView> sampleViews(const ViewSamplingParams& params, const Eigen::Vector3f& centre);

/// The views whose camera sits within `max_polar_deg` of their hemisphere's up axis
/// (TrainingView::up), seen from `centre`: for objects that only ever stand upright under a
/// camera looking down, the rest of the hemisphere is templates that can only match wrongly.
std::vector<TrainingView> viewsAbove(const std::vector<TrainingView>& views, const Eigen::Vector3f& centre,
                                     float max_polar_deg);

/// `views` less the views that turn past `inplane` (those the whole turn near a pole added,
/// ViewSamplingParams::full_turn_within_deg) and show what a view within it already shows: the
/// same rotation, or the same after one of `symmetries`, within `tolerance_deg`. With several
/// resting poses most of the whole turn is seen from another pole's views already (the 40 mm
/// bracket keeps 6 % more templates); a spark-plug key lying flat gains the turns no view of it
/// had (18 % more). The order is kept.
std::vector<TrainingView> dropTurnsShownAlready(const std::vector<TrainingView>& views, const SteppedRange& inplane,
                                                const std::vector<NearSymmetry>& symmetries, float tolerance_deg);

// ---- LINEMOD templates -----------------------------------------------------------------

struct TemplateFeature {
  int x = 0, y = 0;  ///< pixels at the template's level, relative to its top-left corner
  uint8_t bin = 0;   ///< orientation bin 0..7
  Modality modality = Modality::ColourGradient;
  bool operator==(const TemplateFeature&) const = default;
};

struct TemplateLevel {
  int width = 0, height = 0;  ///< pixels at this level
  std::vector<TemplateFeature> features;
  bool operator==(const TemplateLevel&) const = default;
};

/// One view of one object; levels finest first, as many as FeatureParams::T.
struct LinemodTemplate {
  std::vector<TemplateLevel> levels;
  bool operator==(const LinemodTemplate&) const = default;
};

/// Cells (pixels / T) a template spans at a level, as LINEMOD counts them: (size - 1) / T + 1.
inline int templateCells(int size_px, int T) { return size_px <= 0 ? 1 : (size_px - 1) / T + 1; }

/// Throws InputError when a template has the wrong number of levels, no features, a negative
/// or out-of-range position, a bin outside 0..7, or a modality that FeatureParams switches off.
void validateTemplates(const std::vector<LinemodTemplate>& templates, const FeatureParams& params);

// ---- training and bank files ----------------------------------------------------------

struct TrainingParams {
  ViewSamplingParams views;
  /// Quantization and pyramid, the same as detection uses (T = {5, 8} by default).
  FeatureParams features;
  /// Features per modality per pyramid level. LINEMOD: 63 (more are allowed: sums widen).
  int features_per_modality = 63;
  /// Colour features need a gradient magnitude above this (OpenCV's strong threshold: 55).
  float strong_threshold = 55.f;
  /// Focal lengths of the camera the bank is for: templates are scale-specific.
  Camera camera;
  /// The object looks the same under some rotation (evaluation uses ADI instead of ADD).
  bool symmetric = false;
  /// Near-symmetries (findNearSymmetries) are turns that map the surface onto itself within
  /// this share of the diameter; the detector lets colour choose among them. 0: none looked for.
  float near_symmetry_tolerance = 0.03f;
};

/// Throws InputError naming the bad value.
void validateTrainingParams(const TrainingParams& params);

/// A part across fewer cells of LINEMOD's coarsest level than this at the nearest training
/// distance is too small to tell from its neighbourhood: its few features fit any screw head or
/// part end (an 11 mm nut at 0.36 m, 1.1 cells, fired on screw heads all over a real pile).
/// `vkpose train` refuses it unless --allow-small.
inline constexpr float kMinPartCells = 2.f;
/// A part narrower than this many cells of LINEMOD's coarsest level at the nearest training
/// distance (its width: the middle of its three extents, a rod's or a screw's diameter) is a
/// line there. LINEMOD's orientations have no polarity, so a straight edge, a rod or a bin's
/// rim matches it as well as the part does: a 48 mm M3 screw (5.5 mm wide, 0.6 cells at 0.3 m)
/// fired on the rods and rims of metal piles, 11-51 wrong a pile and none right. `vkpose train`
/// refuses it unless --allow-small.
inline constexpr float kMinWidthCells = 1.f;

/// How large the part looks where it is trained and what the sensor resolves there, the
/// evidence a detection of it can have (`vkpose train` prints summary()).
struct PartSizeEvidence {
  float diameter_m = 0.f, thinnest_m = 0.f;  ///< largest and smallest extent (bounding box side)
  float width_m = 0.f;                        ///< the middle extent: narrower than this from no side
  float nearest_m = 0.f, farthest_m = 0.f;   ///< training distances
  float pixels_near = 0.f, pixels_far = 0.f;  ///< the diameter in pixels at each
  float cells_near = 0.f, cells_far = 0.f;    ///< the same in cells of LINEMOD's coarsest level
  float width_cells_near = 0.f;               ///< the width in those cells at the nearest distance
  float thin_pixels_far = 0.f;                ///< the thinnest extent in pixels at the farthest
  float pixel_mm_near = 0.f, pixel_mm_far = 0.f;  ///< what one pixel spans there, millimetres
  /// Under kMinWidthCells wide at the nearest distance: a line to LINEMOD's coarsest level.
  bool line_like() const { return width_cells_near < kMinWidthCells; }
  /// Under kMinPartCells across, or line_like(), at the nearest distance.
  bool too_small() const { return cells_near < kMinPartCells || line_like(); }
  /// Thinner than a structured-light or stereo sensor's matching window resolves (about 4
  /// pixels, half a 7-9 pixel window): its depth merges into what lies behind it.
  bool thin_in_depth() const { return thin_pixels_far < 4.f; }
  /// One or two sentences for `vkpose train`.
  std::string summary() const;
  /// Why training refuses it (too_small()), with what to do instead.
  std::string refusal() const;
};
PartSizeEvidence partSizeEvidence(const Mesh& mesh, const TrainingParams& params);

/// What a user should know before training `mesh` with `params`, one sentence each (empty:
/// nothing): today, an object under about 2.5 cells of LINEMOD's coarsest level across at the
/// farthest training distance, whose views give too few features. `vkpose train` prints them,
/// vkpose.train() raises them as Python warnings.
std::vector<std::string> trainingWarnings(const Mesh& mesh, const TrainingParams& params);

/// What training decides about an object before it renders anything: the up axis, the other
/// poses it rests in, and the views. `vkpose train` and Python's vkpose.train() both take it
/// from planTraining, so that a bank trained either way with the same options is the same.
struct TrainingPlan {
  UpAxisChoice found;  ///< findUpAxis's verdict, also where an up axis was given
  /// The other poses it rests in (otherRestingUps), whether trained or not (those trained are
  /// params.views.other_ups); none with the full sphere, which sees every side.
  std::vector<Eigen::Vector3f> other_ups;
  std::vector<TrainingView> views;  ///< sampleViews then viewsAbove
};

/// Fills in `params.views`: `up` from findUpAxis where `auto_up` (else it is kept as given), and
/// `other_ups` where trainsOtherRestingPoses(`resting`) and not the full sphere, and
/// `full_turn_within_deg` (`full_turn_within_deg` where given, else kPileFullTurnWithinDeg for
/// a part trained to lie in a bin and 0 otherwise); then samples the views within
/// `max_view_angle_deg` of each hemisphere's top. Throws InputError for a `resting` other than
/// auto, all, up, or when no view is left.
TrainingPlan planTraining(const Mesh& mesh, TrainingParams& params, bool auto_up, const std::string& resting,
                          float max_view_angle_deg, std::optional<float> full_turn_within_deg = std::nullopt);

/// Depth and normals of a rendered template, sampled every `stride` pixels over the object's
/// box: cell (i, j) is template pixel (x0 + j * stride, y0 + i * stride) (level 0, relative
/// to the template's top-left corner; x0, y0 <= 0 when the object reaches past the features).
struct TemplateCrop {
  int x0 = 0, y0 = 0;
  int stride = 1;
  int cols = 0, rows = 0;
  std::vector<uint16_t> depth_01mm;  ///< depth in 0.1 mm units, 0 = not the object
  std::vector<int8_t> normals;       ///< 3 per cell: unit camera-frame normal * 127
};

/// Cells per side of a template crop, at most.
constexpr int kCropCells = 24;

struct BankTemplate {
  LinemodTemplate linemod;  ///< features per pyramid level
  Pose pose;                ///< object-to-camera pose the template was rendered at
  float distance = 0.f;     ///< training distance d, metres (camera to the object's centre)
  float inplane_deg = 0.f;
  int viewpoint = 0;
  /// Where the object's centre projects, in level-0 pixels from the template's top-left.
  float anchor_x = 0.f, anchor_y = 0.f;
  TemplateCrop crop;
};

/// Everything detection needs about one object.
struct TemplateBank {
  std::string object;        ///< the mesh file's stem
  uint64_t mesh_hash = 0;    ///< FNV-1a 64 of the mesh file
  float diameter = 0.f;      ///< metres
  bool symmetric = false;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  ///< the point the cameras look at (object frame)
  /// The mesh the bank was trained from (metres): the pose stages render it and compare it
  /// with the scene, so a bank file is all that detection needs.
  Mesh mesh;
  TrainingParams params;
  std::vector<BankTemplate> templates;
  /// Turns that map the mesh onto itself within params.near_symmetry_tolerance (version 4;
  /// older banks find them from their mesh when loaded).
  std::vector<NearSymmetry> near_symmetries;

  std::vector<LinemodTemplate> linemodTemplates() const;
};

/// Called after each batch of views: (views done, views in all).
using TrainingProgress = std::function<void(std::size_t, std::size_t)>;

/// Per-stage training times.
struct TrainingTimings {
  double render_ms = 0, features_ms = 0, total_ms = 0;
  std::size_t dropped = 0;  ///< views with too few features to make a template
};

/// Renders every view of `params.views` on the GPU and extracts LINEMOD features from each,
/// as LINEMOD selects them: colour gradients on the silhouette and strong inner edges
/// (5x5 non-maximum suppression, magnitude above the strong threshold), normals inside the
/// eroded mask (centres of uniform regions first), spread out over the object.
TemplateBank trainTemplates(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                            const TrainingProgress& progress = {}, TrainingTimings* timings = nullptr);

/// The same for an explicit list of views (e.g. a subset of sampleViews()); views that differ
/// only in in-plane rotation must be consecutive to share a rendering.
TemplateBank trainTemplatesFromViews(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                                     const std::vector<TrainingView>& views, const TrainingProgress& progress = {},
                                     TrainingTimings* timings = nullptr);

/// Bank files (.vkpb): a versioned header, the training parameters, all templates, and an
/// FNV-1a 64 checksum of everything before it.
// 2: the mesh is stored; 3: the up axis (2 reads as +z); 4: near-symmetries; 5: other resting ups;
// 6: the whole turn in-plane near the poles (older read as 0)
constexpr uint32_t kBankVersion = 6;
void saveBank(const TemplateBank& bank, const std::string& path);
/// Throws InputError naming the file and the problem: missing, not a bank, another version,
/// truncated, or a checksum mismatch.
TemplateBank loadBank(const std::string& path);

// ---- banks cached between runs --------------------------------------------------------

/// FNV-1a 64 of what a bank is trained from: the bank format version, the mesh as the bank
/// stores it, the training parameters and every view.
uint64_t trainingKey(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views);

/// Where banks are cached: $VKPOSE_CACHE_DIR, else $XDG_CACHE_HOME/vkpose/banks, else
/// $HOME/.cache/vkpose/banks; empty when none of them is set.
std::string defaultBankCacheDir();

struct CachedBank {
  TemplateBank bank;
  bool from_cache = false;  ///< read back rather than trained
  std::string path;         ///< the cache file (empty without a cache folder)
};

/// The bank of `mesh` trained from `views`: read from `cache_dir`/NAME-KEY.vkpb when it is
/// there and sound, else trained and written there (beside and renamed, so a reader in another
/// process never sees half a file). A damaged cache file is trained again and replaced. An
/// empty `cache_dir` trains without caching.
CachedBank loadOrTrainBank(const GpuContext& ctx, const Mesh& mesh, const TrainingParams& params,
                           const std::vector<TrainingView>& views, const std::string& cache_dir,
                           const TrainingProgress& progress = {});

}  // namespace vkpose
