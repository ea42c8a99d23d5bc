#pragma once
// Where the robot may be when it does not know: a set of pose hypotheses, each a Gaussian
// (pose and covariance at the capture time of the last frame that weighed it) carried between
// frames by the shared dead reckoning, and weighed by BOTH cameras with one likelihood each:
//  - omni frames: the global localizer's score of the hypothesis (matched directions, lamps in
//    clear view not seen, blobs nothing explains) at the pose least squares refines it to, plus
//    the Gaussian likelihood of that refinement under the hypothesis's prediction;
//  - ceiling frames: each lamp in full view labelled from the hypothesis's prediction, a lamp
//    with no map lamp inside its gate is unexplained, map lamps predicted well inside the view
//    and not seen are missing, and the pose measured from the labelled lamps updates it.
// The map bounds motion: a hypothesis carried out of every region (through a wall) dies.
//
// Hypotheses are born from omni global localization, enumerating every place the image fits
// (GlobalLocalizer::enumerate). The set is COMPLETE once one image's enumeration held every such
// place: from then on the true pose is one of the hypotheses (or the set is reset when every
// hypothesis is contradicted), so a posterior over them means something. A pose is published
// (winner()) only from a complete set whose leader holds at least `publish_posterior` of the
// weight and `publish_ratio` times the runner-up's likelihood; otherwise the answer is "one of
// these", with every hypothesis and its weight.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lampnav/core/robot_description.hpp"
#include "lampnav/core/time.hpp"
#include "lampnav/fusion/ceiling_pipeline.hpp"
#include "lampnav/fusion/global_localizer.hpp"
#include "lampnav/fusion/odometry_track.hpp"
#include "lampnav/graph/map.hpp"

namespace lampnav::fusion {

struct HypothesisSetOptions {
  double publish_posterior = 0.999;  // the leader's share of the weight needed to publish it
  double publish_ratio = 1000;       // and its likelihood ratio over the runner-up
  // On a floor that swings the cameras f times the ceiling pipeline's tilt_sigma (the swing
  // CeilingContinuity learns; f at least 1), both margins are raised to the f-th power: the
  // leader needs publish_ratio^f over the runner-up and the others at most (1 -
  // publish_posterior)^f of the weight. The hypotheses are weighed with the configured models
  // (births_follow_swing, below), which trust each image more than such a floor allows: on three
  // sweeps of 64 drives each, floors of 0.8 and 1.5 degrees, 19 wrong fixes with the configured
  // margins and 6 with these, for 7 to 11 % more time unsure (docs/hypotheses.md, "Margins that
  // follow the floor's swing").
  bool publish_follows_swing = true;
  // And until the floor's swing is measured (the localizer's continuity check, its first
  // tilt_min_samples lamps seen twice), f is the largest swing it could measure (max_tilt_sigma
  // over tilt_sigma, 8.0 by default): on a held-out sweep a half-turn twin was published 2.5 s
  // into a drive, before the floor was measured (docs/hypotheses.md, "A floor not measured yet").
  bool unmeasured_floor_swings_most = true;
  // Omni frames that weighed the set since it became complete before it may publish (the image
  // that completed it counts), unless that image was searched alone (no places carried into it)
  // and the map explains all it shows (no blob beyond the map's places): then one image decides,
  // as for a robot carried in a mapped building. A complete set is born from one image's search,
  // and a search can call itself complete without the truth (places carried from an image with
  // two seeds, one off its lamp; the truth charged for lamps a map of part of a building lacks).
  // The images that follow, a metre on, mostly contradict a set of wrong places and start it
  // again; published at once, such sets gave 13 wrong fixes on 60 drives of the office on maps
  // built from one drive, without their start; 2 at 3 (docs/hypotheses.md, "Three images before
  // a set publishes").
  int min_omni_frames = 3;
  // And when the image that completed the set shows lamps beyond the map's places (a map of part
  // of a building: the robot may be where the map has nothing, and a corridor there looks like a
  // corridor of the map), the robot must also have travelled this far (m) since: a set of places
  // the robot is not at is then carried through the map's walls or contradicted by what the drive
  // shows next. Carried off a map built from one drive, robots in the office's corridors the map
  // lacks were published on its look-alike corridor: 17 wrong fixes on 25 drives without their
  // start, 14 on 24 with it (docs/hypotheses.md, "Carried off a map of part of a building").
  double partial_view_travel_m = 8.0;
  int max_hypotheses = 512;    // an image fitting more places leaves the set incomplete
  int symmetry_check_max = 8;  // at most this many hypotheses are checked for twins
  // While the set is incomplete, the next enumeration waits for this much travel (m) or turn
  // (deg): a view a metre on fits the same places, and enumerating costs up to 0.7 s.
  double enumerate_every_m = 2.0, enumerate_every_deg = 30.0;
  // While the set is incomplete, the places each image allows are carried to the next
  // enumeration, which keeps only the poses within this gate of one of them (growing with the
  // travel as odometry's sigma does, three times over): the places the drive so far allows.
  // Each place adds up what the images said of it (each capped at frame_cost_cap, an image
  // that did not allow it at all costing the cap); one costing place_cost_max more than the
  // likeliest is dropped.
  bool carry_places = true;
  // The gate is about twice a place's own error (a seed pair's pose: up to 0.4 m and 6 degrees
  // off on rendered views), and well under the lamp spacing that separates look-alike places.
  double place_gate_m = 1.0, place_gate_deg = 12.0;
  double place_cost_max = 30.0;
  // An image that fits some place better than every place the drive allows, by more than this
  // (-2 ln of the likelihood ratio; 30 is 3e-7), says the places are stale: the robot was carried
  // while lost, which the wheels do not see. The set starts again from that image. (A kidnap
  // while lost, 2026-12-03: the drive's places scored 102 on the image that scored 2.4 at the
  // truth, and the set, kept to them, published a twin 8 m off.)
  double stale_places_cost = 30.0;
  // Images taken within this distance (m, of the robot) of the last enumeration (a turn on the
  // spot, the omni camera seeing the same ceiling turned) add no cost to the places: their
  // evidence is the last image's again. Counted anew, four images of one spot in a turn dropped
  // the truth for its twin, whose look the spot favoured by 9 to 15 an image
  // (docs/hypotheses.md).
  double station_m = 0.25;
  // An image's cost a place is let off (EnumerationPrior::view_allowance). The truth's own
  // cost on rendered views has a median of 2 and is often 4.6 (a lamp missed, when a miss
  // cost that) or 6 (a blob odd), so these add up over a long drive; but letting them off
  // slows the pruning: on the 1,000-node kidnaps, 4.6 fixed 5 of 10 and 2 fixed 9 of 10 after
  // a median of 163 m, against 9 of 10 after 108 m with none (docs/hypotheses.md).
  double place_allowance = 0.0;
  double drop_ratio = 1e-9;      // hypotheses below this likelihood ratio to the best die
  double birth_ratio = 1e-4;     // an image gives birth to the places within this ratio of
                                 // its best (the truth's own noise stays far inside it)
  double frame_cost_cap = 12.0;  // -2 ln L one omni frame can cost a hypothesis: one odd
                                 // frame (a person under a lamp) never decides alone
  // An image whose likeliest place's lamps misfit by more than this (-2 ln L of its matched
  // lamps and the tilt they needed, its missed lamps and unexplained blobs left out) fits no
  // place as an image fits the truth: a floor bump past the models, a person under the lamps.
  // Its newborns are weighed as every later frame weighs them, each at most frame_cost_cap
  // behind the likeliest, and it neither decides alone nor completes the set: the truth may not
  // be among them. Completed by one (best 59, the truth 36 behind it and not born) on a floor
  // swinging the cameras 1.5 degrees, a set published a place 60 m along the truth's corridor
  // (docs/hypotheses.md, "An odd image completes no set").
  // Born from such an image (misfit 52) after a false alarm on a floor swinging the cameras 1.5
  // degrees, a twin corridor 28 m off led the truth by 39 and was published for 22.7 s. No image
  // of the default floor's office drives passed 4.4, nor of the museum's kidnaps 4.1, nor of the
  // grid office's and the 4 m ceiling's tests 12.1 (docs/hypotheses.md, "An image that fits no
  // place").
  double odd_image_misfit = 20.0;
  // The same bound for an image in which the hypothesis matches many lamps in clear view: at
  // least this much misfit for each of them. The misfit is mostly theirs (near lamps, sharp
  // directions), summed, so a bound that does not grow with them calls the place that explains
  // more of the image odd sooner than one that explains less. Under two rows of lamps 3 m up on a
  // floor swinging 1.2 degrees, the truth matched 17 lamps in clear view and misfit 25.1, its
  // twin 30 m off (a room's lamps beside the truth, none beside the twin, left to the far
  // account) matched 12 and misfit 15.9: the truth was contradicted, and the twin published
  // (docs/hypotheses.md, "Images of many lamps"). Under one row a place has at most about 10
  // lamps in clear view, where the bound stays odd_image_misfit.
  double odd_image_misfit_per_lamp = 2.0;
  // An image odd for a hypothesis at the pose its refinement reached may say only that the
  // hypothesis is off by more than its covariance allows, and the refinement, matching within
  // that covariance, settled beside the truth. So the poses within odd_image_search_m and
  // odd_image_search_deg of it that the image allows are searched for, as a search finds them
  // (GlobalLocalizer::enumerate, within a gate). The best that scores better and is not odd
  // moves the hypothesis there (its covariance the image's) if the move's innovation under the
  // hypothesis's covariance, which it is charged, is below contradiction_cost; the image then
  // does not contradict it. Only the odd_image_search_hypotheses likeliest are searched about;
  // 0 m turns the search off. Under a ceiling 0.8 m above the omni camera, on a floor swinging
  // 1.2 degrees, the truth misfit 20.5 and 22.4 with 6 to 8 lamps: contradicted, its twin 18 m
  // off was published; a pose near it misfit 14.5. Moves not bounded by their cost, or gates of
  // 0.8 m and more, rescued look-alike places after carries (no image contradicted them all, the
  // set did not start again) and made other wrong fixes (docs/hypotheses.md, "A hypothesis off by
  // more than it knows", the forms tried).
  double odd_image_search_m = 0.6;
  double odd_image_search_deg = 10.0;
  int odd_image_search_hypotheses = 8;
  // What an omni image that contradicts a hypothesis costs it (-2 ln L), beyond what its lamps
  // did: the contradiction is evidence of its own. The ledgers charge what repeats once (a lamp
  // out, a spot the map lacks, the far account of blobs beyond the map's places), so a twin
  // that leaves most of every image's blobs unexplained soon pays little for them; the count
  // behind a contradiction (most lamps in clear view unseen, or most blobs unexplained)
  // forgives nothing. On 68 drives of four generated buildings with failed lamps, 15 of the
  // 2,003 images weighed at the truth contradicted it (0.75 %) against 1,815 of 10,025 weighed
  // elsewhere (18 %): 2 ln(18 / 0.75) = 6.4. A twin 40 m off that 13 of 19 images had
  // contradicted, every image costing it about what it cost the truth, was published
  // (docs/hypotheses.md, "Contradictions count").
  double contradiction_cost = 6.4;
  // An omni image that costs a hypothesis more than this in all (-2 ln L: its lamps' directions,
  // the lamps it missed and the blobs no lamp explains, after the ledgers) contradicts it. Of the
  // 2,003 images above weighed at the truth, 2 cost more than 45 (52, early in a set; 93); the
  // first image after a carry into a regular building's other wing cost every hypothesis 54 to
  // 139, and raised the least wrong from 0.995 to 0.9993: published (docs/hypotheses.md,
  // "Contradictions count").
  double odd_image_cost = 45.0;
  // The same for a ceiling frame: ten a second see the same lamps, so their evidence is far from
  // independent. What repeats (a lamp out, off, or not in the map) is counted once by the
  // ledgers (MapErrorCosts); at 2, the first frame that saw a lamp off lost two thirds of what it
  // said, and a building's four turned images stayed in the set.
  double ceiling_cost_cap = 6.0;
  double kept_prior = 0.1;                // the tracking hypothesis's prior after a kidnap alarm
  double merge_m = 0.3, merge_deg = 5.0;  // hypotheses closer than this are one
  // Odometry error while carried: position sigma grows by sigma_per_m per metre travelled, yaw
  // by sigma_yaw_deg_per_m (deg per metre); the floor: sigma_m, sigma_yaw_deg.
  double sigma_m = 0.02, sigma_per_m = 0.03;
  double sigma_yaw_deg = 0.5, sigma_yaw_deg_per_m = 1.0;
  double wall_margin_m = 0.4;       // a pose this far outside every region went through a wall
  double omni_bump_sigma_m = 0.06;  // floor bumps added to an omni refinement's covariance
  double omni_bump_sigma_deg = 0.15;
  double birth_sigma_m = 0.1, birth_sigma_deg = 1.5;  // a hypothesis born from one image
  // On a floor that swings the cameras more than the ceiling pipeline's tilt_sigma (the swing
  // CeilingContinuity learns), both birth sigmas grow by the swing over tilt_sigma: one image
  // places the robot that much less well. Held at 1.5 degrees on a floor swinging 1.2 to 1.4, a
  // truth born 6 degrees off was refined away from itself after a sharp turn, contradicted, and its
  // half-turn twin published 51 m off (the oblique lattice of docs/hypotheses.md, "Newborns on a
  // swinging floor"). The weighing keeps the configured models (docs/localization.md).
  bool births_follow_swing = true;
  double ceiling_miss_cost = 4.6;      // -2 ln 0.1, a lamp in clear view not seen
  double ceiling_spurious_cost = 6.0;  // a lamp in full view no map lamp explains
  // The least position uncertainty the ceiling lamps of a hypothesis not yet fitted to ceiling
  // lamps are labelled with (Hypothesis::ceiling_fitted). An omni image places a newborn to 10
  // to 30 cm on a rough floor with the wheels off, and the gate of its own covariance (12 cm)
  // refused the lamps a right place born 30 cm beside its corridor's axis saw overhead: each was
  // charged as a lamp the map lacks, frame after frame, while its quarter-turn twin, born off
  // along its corridor, took its lamps and was pulled onto them. The truth fell behind by 12 in
  // two seconds and the twin, 35 m off, was published (docs/hypotheses.md, "Failed lamps and
  // carries"). A hypothesis off by more than the gate (3 sigma) still pays for the lamps it
  // cannot label, and one that labels them still pays for a fit past what the map's errors
  // explain (fit_gate_probability). Once fitted, its covariance is its own again: with the floor
  // on every hypothesis, 4 of 20 unknown starts on a map 5 cm off were fixed at a look-alike
  // place, against 3 (lamps drawn 10 cm off were labelled).
  double ceiling_label_sigma_m = 0.2;
  // A map is not the building (fusion/src/map_evidence.hpp). The most a map lamp's absences and
  // misfits cost a hypothesis, over all its frames together: what one omni frame's miss costs
  // (-2 ln 0.01, one lamp in a hundred out), so that a lamp that is out, or off, never decides
  // alone (publish_ratio is 13.8). A lamp that is out stays out: charged in every frame that had
  // it in view, one failed lamp of the truth's made its look-alike place, which has no lamp
  // there, a thousand times likelier within a second, and that place was published as certain
  // 20 m off (a 100-node building with a tenth of its lamps out; docs/hypotheses.md).
  double lamp_out_cost = 9.2;
  // The same for a spot where lamps are seen and the map has none (a lamp put up since, one the
  // survey missed), by both cameras together: sightings within stray_radius_m of one another
  // (widened with the distance for the omni camera's far blobs) are one spot.
  double unmapped_lamp_cost = 9.2;
  double stray_radius_m = 0.5;
  // An omni blob no lamp explains counts as a spot only where it places a lamp within this (m,
  // StraySighting::reach). A map of part of a building leaves the omni camera dozens of far blobs
  // each image: merged into wide spots, they cost the places too little to tell a pose 17 cm and
  // 6 degrees off from the tracked one.
  double stray_reach_max_m = 1.0;
  // The omni blobs no lamp explains that place no lamp better than stray_reach_max_m (far off,
  // or below the lamps' horizon), all together: at most this over all of a hypothesis's frames.
  // Such a blob may be a lamp the map lacks, seen again in every image, and where it is cannot
  // be told, so the far sightings of every lamp the map lacks share one account. Charged in
  // every image, they made the truth's twin, whose part of the map has those lamps, certain
  // (11 of 20 starts on a map lacking 5 % of its lamps, docs/hypotheses.md). At 9.2 (one lamp
  // the map lacks), the far view alone never makes a place certain (publish_ratio is 13.8);
  // lamps seen near, and lamps the map has and the image lacks, still do.
  double far_stray_cost_max = 9.2;
  // What each blob the far account holds whose lamp the image places well (within
  // stray_reach_max_m) but beyond every place of the map costs an image at least, the account
  // spent or not. Were such a blob free once the account is spent, leaving a blob unexplained
  // would be cheaper than explaining it: a twin 48 m along the truth's corridor left up to 23 of
  // each image's blobs (lamps the truth matched) beyond the map's end, paid nothing for them after
  // its first images, and was published 48 m off (a regular building with failed lamps,
  // docs/hypotheses.md, "Blobs beyond the map"). 2 is a matched blob's expected cost (a
  // direction's chi-square, two degrees of freedom); 0.5 and 1 still published that twin. On a
  // whole building's map the truth leaves no such blob; on a map of part of one it leaves those
  // of the lamps past the map's ends, and pays for them alike wherever it is.
  double beyond_map_blob_cost = 2.0;
  // Whether an omni blob no lamp explains, whose lamp would lie beyond every place of the map
  // (farther than its StraySighting::reach from each), is charged to a spot like the others
  // (true) or to the far account (false). A map built from one drive holds the corridors the drive
  // took: at its ends the building goes on, and the truth sees lamps there in every image. Charged
  // a spot each, they made poses whose other end of the map explains them likelier than the truth
  // (a map of part of the office, docs/hypotheses.md). Beyond a whole building's places no lamp is
  // seen.
  bool count_beyond_map = false;
  // A row of lamps the map does not hold, seen by the omni camera beside a row it holds (within
  // row_beside_m, at least row_beside_min_lamps of them, spaced like the mapped row; asked of the
  // likeliest eight hypotheses each omni frame, fusion/src/unmapped_rows.hpp): no leader is
  // published until the robot has travelled row_beside_memory_m since one was seen. A wide
  // corridor mapped under one of its two rows looks the same from under either, and a robot under
  // the unmapped row, off the map's places, was placed under the mapped one: published 2.9 m off
  // after 75 s; 19 wrong fixes on 16 drives with rows 1.2 to 2.2 m apart (docs/hypotheses.md, "A
  // row the map does not hold"). row_beside_m = 0 turns the check off.
  double row_beside_m = 2.5;
  int row_beside_min_lamps = 3;
  double row_beside_memory_m = 10.0;
  // The strays of this many omni images (a hypothesis's last) are looked at together: the row's
  // far lamps are placed too loosely and its near ones often explained, so an image seldom shows
  // three of them (one or two an image with rows 1.2 m apart).
  int row_beside_images = 4;
  // Only strays placed within this (m, StraySighting::reach) count; the row's lamps 5 m along
  // are placed within about 1 m.
  double row_beside_reach_m = 1.5;
  // The leader is not published while this many of the last unexplained_window ceiling frames
  // that weighed it (at most 32) each held a lamp in full view where it has no map lamp: the
  // tracking filter's kidnap monitor calls a pose with as many lost (KidnapMonitorOptions,
  // contradicting_frames of window_frames, 4 of 10), so such a fix would be taken back within a
  // second, and it is seldom the truth. A wide corridor mapped under one of its rows 1.2 m apart
  // (the ceiling camera sees the other row whole) made 2 wrong fixes on a drive under the mapped
  // row, each called lost 1.3 s later, one in the look-alike corridor 15 m off (docs/hypotheses.md,
  // "A row the map does not hold"). 0 turns the check off.
  int publish_unexplained_frames = 4;
  int unexplained_window = 10;
  // How far the map's lamps may be off the building's (m), in the set's labelling and pose fits:
  // `map build` leaves 2 to 4 cm (docs/mapping.md). The tracking filter keeps the ceiling
  // pipeline's own, tighter, figure.
  double map_sigma_m = 0.03;
  // A ceiling frame's pose fit costs a hypothesis only past this quantile of its chi-square (3
  // degrees of freedom; with map_sigma_m in it): within it, the misfit is the map's errors. A
  // hypothesis 17 cm and 6 degrees off, born from one omni image beside the tracked pose, pays.
  double fit_gate_probability = 0.99;
  // An omni frame's cost within this of the best frame's is a tie. What a map's errors leave in
  // an image after each lamp is counted once (its far blobs, the tilt each image fits): on a map
  // 5 cm off, 0.2 to 1.5 an image against the truth, image after image, which published a twin
  // 20 m off after 40 m. Between twins, differences up to 2 an image, each way in turn, added up
  // like a random walk past publish_ratio: with 1, 8 and 10 wrong fixes on the thirteenth
  // sweep's 64 drives and 64 held out, 6 and 7 with 2 (docs/hypotheses.md, "Small differences
  // between twins are ties").
  double omni_tie_cost = 2.0;
  // A frame's hypotheses weighed on every core (up to four), or on the calling thread only; the
  // results are the same to the last bit.
  bool weigh_in_parallel = true;
  void validate() const;  // throws InputError naming the field
};

// What a map that is not the building has cost one hypothesis so far, each error bounded over
// all its frames together (fusion/src/map_evidence.hpp says why).
struct MapErrorCosts {
  // Each map lamp's absences (at most HypothesisSetOptions::lamp_out_cost each, in all).
  std::vector<std::pair<const graph::Lamp*, double>> lamps;
  // Each map lamp's misfit: the worst a frame found it off, or seen where the gate would not
  // label it (at most lamp_out_cost each).
  std::vector<std::pair<const graph::Lamp*, double>> misfits;
  // Each spot where lamps were seen and the map has none (at most unmapped_lamp_cost each).
  struct Stray {
    Eigen::Vector2d at = Eigen::Vector2d::Zero();  // in the map, at the lamps' usual height
    double radius = 0;                             // sightings within it are the same spot
    double spent = 0;
  };
  std::vector<Stray> strays;
  // What the omni blobs no lamp explains that place no lamp well enough for a spot have cost, all
  // together (at most HypothesisSetOptions::far_stray_cost_max).
  double far_strays = 0;
};

enum class HypothesisOrigin { omni, kept };  // born from an omni image; the tracking estimate
const char* to_string(HypothesisOrigin origin);

struct Hypothesis {
  int id = 0;
  HypothesisOrigin origin = HypothesisOrigin::omni;
  Stamp stamp;                                               // capture time it stands at
  Pose2 pose;                                                // robot base in the map, at stamp
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // x, y, yaw
  Pose2 odometry;                                            // the dead-reckoned pose at stamp
  double log_weight = 0;      // log prior + log likelihood of every frame since the set began
  double weight = 0;          // posterior share (the set's weights sum to 1)
  double last_cost = 0;       // -2 ln L of the last frame that weighed it
  bool contradicted = false;  // the last omni frame plainly contradicted it (never published then)
  MapErrorCosts map_costs;    // what the map's errors have cost it so far
  // Its pose has been fitted to ceiling lamps (or came from the tracking filter, which was): its
  // covariance then says how well it is placed. Before, it says what one omni image's fit and the
  // birth allowance claim, which floor bumps and the wheels between images exceed.
  bool ceiling_fitted = false;
  const graph::Node* node = nullptr;
  // The blobs of its last omni images that no lamp explained, each placed on the ceiling from
  // its image, and how many images ago (0: the last).
  std::vector<StraySighting> strays;
  std::vector<int> stray_age;
  // Adds an image's strays, and forgets those of `images` images ago and before.
  void keep_strays(const std::vector<StraySighting>& latest, int images);
  // The ceiling frames that weighed it, newest in bit 0: set where a lamp in full view had no map
  // lamp to be (HypothesisSetOptions::publish_unexplained_frames).
  std::uint32_t unexplained_frames = 0;
};

// A row of lamps the omni camera sees that the map does not hold, beside a row it holds.
struct UnmappedRow {
  int lamps = 0;        // in the row
  double offset_m = 0;  // from the mapped row, across
  double length_m = 0;  // from its first lamp to its last
};

// Why the set is as it is (for events, logs and people).
enum class HypothesisVerdict {
  empty,       // no hypothesis: nothing seen yet, or every one was contradicted
  incomplete,  // some hypotheses, but the images fit more places than were enumerated
  ambiguous,   // complete, several hypotheses hold the weight
  symmetric,   // ambiguous, and the building maps onto itself from one hypothesis to the others
               // (every lamp onto a lamp alike): no motion and no camera can ever decide
  decided,     // complete, one hypothesis holds it (winner())
};
const char* to_string(HypothesisVerdict verdict);

class HypothesisSet {
 public:
  // `ceiling_camera` and `omni` (the global localizer, sharing its lamp index) may be null: that
  // camera then weighs nothing. Throws InputError for bad options.
  HypothesisSet(const graph::TopologicalMap& map, const CameraDescription* ceiling_camera,
                const GlobalLocalizer* omni, const CeilingPipelineOptions& ceiling_options,
                const HypothesisSetOptions& options = {});
  ~HypothesisSet();
  HypothesisSet(HypothesisSet&&) noexcept;

  // Forgets every hypothesis; the set is empty and incomplete, `why` in words.
  void clear(const std::string& why = "no omni image yet");
  // After a kidnap alarm: the estimate the robot was tracking stays a hypothesis, at
  // `kept_prior`, until the images decide (a false alarm costs nothing but a few frames).
  void keep(Stamp stamp, const Pose2& pose, const Eigen::Matrix3d& covariance,
            const OdometryTrack& odometry);

  // The floor swings the cameras `factor` times the configured tilt (CeilingContinuity's learnt
  // swing over its tilt_sigma): a newborn's pose is held that much more loosely
  // (births_follow_swing). The margins to publish are raised to the power `publish_factor`
  // (publish_follows_swing): `factor` once the swing is measured, and before that the largest
  // swing the measurement could find, `measured` false (the localizer's start, docs/hypotheses.md,
  // "A floor not measured yet"). Below 1 counts as 1.
  void set_floor_swing(double factor, double publish_factor, bool measured);

  // One omni frame captured at `stamp`: every hypothesis weighed and refined. While the set is
  // incomplete the hypotheses are born again from each image (only the kept estimate carries
  // its weight over). A frame that plainly contradicts every hypothesis starts the set again.
  void omni(Stamp stamp, const vision::OmniDetection& detection, const OdometryTrack& odometry);
  // The lamps of one ceiling frame (full and completed views are used).
  void ceiling(Stamp stamp, const std::vector<vision::LampDetection>& lamps,
               const OdometryTrack& odometry);

  // Best first.
  const std::vector<Hypothesis>& hypotheses() const;
  bool complete() const;
  HypothesisVerdict verdict() const;
  std::string why() const;  // the verdict in words
  // The leader, when the set is decided.
  const Hypothesis* winner() const;
  // A hypothesis carried to `t` by odometry (pose and covariance).
  Hypothesis carried(const Hypothesis& h, Stamp t, const OdometryTrack& odometry) const;

  struct Counts {
    std::uint64_t born = 0, merged = 0, through_walls = 0, dropped = 0, resets = 0,
                  enumerations = 0, complete_enumerations = 0;
    std::uint64_t place_restarts = 0;  // the places the drive allowed all lost: started again
    std::uint64_t stale_places = 0;    // an image alone far likelier elsewhere: started again
    std::uint64_t unmapped_rows = 0;   // omni frames whose leader saw an unmapped row beside
  };
  const Counts& counts() const;
  const HypothesisSetOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lampnav::fusion
