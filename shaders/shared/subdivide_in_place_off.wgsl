// The stand-in for `subdivide_in_place` in the pipelines of the frames that measure rows (the
// sphere under an adaptive rule), which never write a piece in place (`measures_rows`).

#import subdivide_types
#import subdivide_state

fn write_in_place(index: u32, work: PieceWork, tri: ptr<function, InputTriangle>, part: ptr<function, PartPlan>, piece_state: ptr<function, PieceState>) {
}
