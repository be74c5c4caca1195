// Stereo pairs stored as image files: a left and a right folder, as `rcm
// simulate` writes them (left/000000.png, right/000000.png) or as a bag is
// exported (cam0/1403636579763555584.png), or a list file naming the pairs.
//
// Images. The files of a folder whose extension is png, jpg, jpeg, pgm,
// ppm, bmp, tif or tiff (any case); other files, subfolders and hidden
// files (names starting with '.') are ignored. They are sorted by name in
// natural order: runs of digits compare by their value, so 2.png comes
// before 10.png and img9 before img10; other characters compare by byte
// value; names equal in that order ("7.png", "007.png") by plain byte
// order. Folders whose names are timestamps (below) are sorted by time.
//
// Pairing, without a list file, never guesses:
//   - every name (stem and extension) is in both folders: pairs by name,
//     in the order of the left folder;
//   - no name is in both folders and both hold as many images: pairs by
//     sorted order (cam0_0001.png with cam1_0001.png); when both folders'
//     names are timestamps, the two stamps of every pair must be less than
//     half the median frame interval apart;
//   - otherwise (some names in both and some not, or no shared name and
//     different counts) an error with the counts and the first unpaired
//     names: write a list file to say which images go together.
//
// Timestamps from file names, decided by the left folder's names (stems):
//   - every stem an integer of 16 or more digits: nanoseconds (the EuRoC /
//     Kalibr export convention), 1403636579763555584 -> 1403636579.763555584
//     seconds;
//   - every stem a decimal number with a point, 1403636579.7635 or 12.5:
//     seconds;
//   - shorter integers (000000, 17) are frame numbers, and names that are
//     not plain numbers carry nothing: the pairs then have no timestamps;
//   - a folder mixing stamps with other names, or nanoseconds with
//     seconds, is an error.
// Timestamps must increase strictly from pair to pair.
//
// List file (StereoFolderOptions::pair_list), one pair per line:
//
//   # left                right               [timestamp, seconds]
//   left/000000.png       right/000000.png    1403636579.763555584
//   cam0/a.png, cam1/a.png, 1403636579.813555456
//
// Fields are separated by whitespace or, on a line holding a comma, by
// commas (then a path may contain blanks). A line whose first non-blank
// character is '#' is a comment; blank lines are skipped. Relative paths
// are relative to the folder of the list file. The third column gives the
// pair's timestamp in seconds, on every line or on none. The pairs keep
// the order of the list, and every listed file must exist.
#ifndef RCM_IO_STEREO_IMAGE_FOLDERS_H_
#define RCM_IO_STEREO_IMAGE_FOLDERS_H_

#include <memory>
#include <string>

#include "rcm/io/stereo_image_source.h"
#include "rcm/util/status.h"

namespace rcm {

struct StereoFolderOptions {
  // The two image folders; both empty when pair_list is given.
  std::string left_dir;
  std::string right_dir;
  // A list file naming the pairs (see above), instead of the folders.
  std::string pair_list;
  // One camera only (rcm calibrate --underwater --left DIR): left_dir
  // alone, each "pair" the left image with an empty right image (and an
  // empty right name), stamps from the left names.
  bool left_only = false;
  FrameSelection selection;

  // Errors: neither the two folders nor a list, only one folder (unless
  // left_only, which takes exactly the left one), a list together with
  // folders, selection.Check().
  Status Check() const;
};

// Lists (does not decode) the images and pairs them as described above,
// then applies options.selection. The pairs' `frame` is their index before
// selection; their names are the two file paths.
//
// Errors (one line, naming the path): options.Check(); "left/: no such
// folder", "left/: not a folder", "left/: no images (looked for .png, ...)",
// the two folders being the same; the pairing and timestamp errors above;
// "pairs.txt:7: ..." for a malformed list line or a missing listed file;
// SelectFrames' errors.
//
// ReadPair decodes the two files (in parallel) as stored: 8-bit gray or
// BGR; BGRA becomes BGR, and a gray image paired with a color one becomes
// BGR too. Errors name the file: an unreadable or corrupt file, a depth
// other than 8 bits ("right/3.png: 16-bit image, expected 8-bit"), and two
// images of a pair that differ in size (naming both files and sizes).
StatusOr<std::unique_ptr<StereoImageSource>> OpenStereoImageFolders(
    const StereoFolderOptions& options);

}  // namespace rcm

#endif  // RCM_IO_STEREO_IMAGE_FOLDERS_H_
