// fiblet — compress tractograms (MRtrix3 .tck, TrackVis .trk, TRX) into
// fiblets (.fft, .fftz), decode them fast, select parts of them.
// Umbrella header: every public header, section by section, in the order
// of the data path.
#pragma once

// ---- Basics ----------------------------------------------------------------
#include "fiblet/error.hpp"     // fiblet::Error, its codes and remedies
#include "fiblet/geometry.hpp"  // Vec3f and the small value types of the API
#include "fiblet/parallel.hpp"  // the library's one worker pool

// ---- Tractograms in and out ------------------------------------------------
#include "fiblet/streamline_io.hpp"      // read / write streamlines whatever the format
#include "fiblet/tractogram_format.hpp"  // a file's format recognised by its content
#include "fiblet/tck.hpp"                // MRtrix3 .tck: streaming reader, atomic writer
#include "fiblet/trk.hpp"                // TrackVis .trk: reader and writer
#include "fiblet/trx.hpp"                // TRX (zip or directory): reader and writer
#include "fiblet/tractogram_space.hpp"   // the reference image space (.trk, TRX headers)
#include "fiblet/streamline_field.hpp"   // per-streamline, per-point and group data
#include "fiblet/source_dtypes.hpp"      // source dtypes a .fft records and gives back
#include "fiblet/image.hpp"              // NIfTI-1/2 and .mif images

// ---- Compress --------------------------------------------------------------
#include "fiblet/resample.hpp"        // fixed-step resampling, point-to-polyline distance
#include "fiblet/direction_code.hpp"  // the 8-bit direction code and its frames
#include "fiblet/encode.hpp"          // one streamline -> blocks (closed loop)
#include "fiblet/compress.hpp"        // the whole tractogram -> .fft pipeline

// ---- The .fft container ----------------------------------------------------
#include "fiblet/fft_format.hpp"             // the layout: header, LUT, blocks, trailer
#include "fiblet/fftz_format.hpp"            // the seekable zstd container (.fftz)
#include "fiblet/fft_file.hpp"               // validated reading: header + LUT up front, blocks on demand
#include "fiblet/checksum.hpp"               // XXH64 integrity chunk, whole-file verification
#include "fiblet/fiber_ends.hpp"             // the ENDS chunk: fibers end where their input does
#include "fiblet/streamline_data_chunk.hpp"  // the DATA chunk: streamline data stored with the blocks
#include "fiblet/output_file.hpp"            // atomic outputs, cleanup on signals

// ---- Index and selection ---------------------------------------------------
#include "fiblet/index_format.hpp"   // which block index version a writer produces
#include "fiblet/block_index.hpp"    // per-block boxes (BIDX chunk) and a hierarchy over them
#include "fiblet/view.hpp"           // camera, frustum, level of detail, block spheres
#include "fiblet/image_mask.hpp"     // an image as a region of interest (tckedit's rule)
#include "fiblet/select.hpp"         // selective decoding: subsets, regions, frustum, LoD
#include "fiblet/fiber_regions.hpp"  // regions tested on fibers already decoded
#include "fiblet/fft_subset.hpp"     // a selection written as a smaller .fft file

// ---- Decode ----------------------------------------------------------------
#include "fiblet/decode.hpp"  // blocks -> points (SIMD decoders), fibers -> TRX-layout arrays

// ---- Measure ---------------------------------------------------------------
#include "fiblet/error_stats.hpp"     // max / mean / RMS / percentiles of position errors
#include "fiblet/geometry_error.hpp"  // decoded vs input both ways, endpoints, lengths
#include "fiblet/compare.hpp"         // a .fft measured against its source
