pub fn scheme_prediction() {} pub struct Prediction;
