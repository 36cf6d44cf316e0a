#pragma once
// Counts of a Dim-cube (square or cube), in one place (STYLE.md §1).

namespace febemesh {

template <int Dim> struct Cube {
  static_assert(Dim == 2 || Dim == 3, "febemesh supports Dim = 2 and 3");
  static constexpr int dim = Dim;
  static constexpr int n_children = 1 << Dim;
  static constexpr int n_corners = 1 << Dim;
  static constexpr int n_faces = 2 * Dim;              ///< facets: edges in 2D, faces in 3D
  static constexpr int n_face_corners = 1 << (Dim - 1);
  static constexpr int n_face_children = 1 << (Dim - 1);
  /// Neighbours across facets, edges and corners (3^Dim - 1).
  static constexpr int n_all_neighbours = Dim == 2 ? 8 : 26;
};

/// Facet f of a cell: axis f/2, on the lower (f even) or upper (f odd) side.
constexpr int face_axis(int f) { return f / 2; }
constexpr int face_side(int f) { return f % 2; }

/// Corner c of a cell: bit d of c set = upper along axis d (same numbering as children).
constexpr bool corner_is_upper(int c, int d) { return (c >> d) & 1; }

}  // namespace febemesh
